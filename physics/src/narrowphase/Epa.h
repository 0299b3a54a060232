#pragma once

// EPA (Expanding Polytope Algorithm): penetration depth, normal and deepest points of two overlapping convex
// supports. Starts from the simplex of a GJK run that found overlap, blows it up to a tetrahedron when GJK
// stopped with fewer points (touching or the origin on a simplex edge), then grows a polytope inside the
// Minkowski difference towards the face closest to the origin. Fixed-capacity polytope: no allocation.

#include "narrowphase/Gjk.h"

namespace cairn::physics
{

struct PenetrationResult
{
    Vec3 mNormal =
        Vec3::UnitY();   ///< Unit, from A towards B: moving B by mNormal * mDepth separates the shapes
    float mDepth = 0.0f; ///< >= 0 up to tolerance
    Vec3 mPointA = Vec3::Zero(); ///< Deepest point of A inside B (on A's surface)
    Vec3 mPointB = Vec3::Zero(); ///< Deepest point of B inside A (on B's surface)
};

class Epa
{
public:
    static constexpr int cMaxIterations = 64; ///< Curved parts converge slowly: stop here with the best face
    static constexpr int cMaxVertices = 128;
    static constexpr int cMaxFaces = 256;

    /// Penetration of A inflated by inInflationA and B inflated by inInflationB, starting from inSimplex,
    /// the simplex of a GJK run on the same inflated supports that reported overlap. Returns false when no
    /// polytope with volume could be built (flat Minkowski difference).
    static bool Penetration(const ConvexSupport& inA, float inInflationA, const ConvexSupport& inB,
                            float inInflationB, const GjkSimplex& inSimplex, PenetrationResult& outResult);
};

} // namespace cairn::physics
