#pragma once

// Shape: the immutable collision volume of a body. Shapes are created once (with validation), then shared
// read-only between bodies and threads through ShapeRef; no member changes after creation, so every const
// method is safe to call from any thread without a lock.

#include "cairn/physics/math/AABB.h"
#include "cairn/physics/math/FunctionRef.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace cairn::physics
{

enum class ShapeType : uint8_t
{
    Sphere,
    Box,
    Capsule,
    ConvexHull,
    TriangleMesh,
    HeightField,
    Compound,
};

const char* ToString(ShapeType inType);

/// Mass, centre of mass and inertia of a shape of uniform density.
struct MassProperties
{
    float mMass = 0.0f;                ///< kg
    Vec3 mCenterOfMass = Vec3::Zero(); ///< In shape-local space
    Mat3 mInertia = Mat3::Zero();      ///< kg m^2, about the centre of mass, in shape-local axes
};

/// A ray as a segment: points mOrigin + t * mDirection for t in [0, 1].
/// The longest ray a world query takes, m: corner to corner of the world (about 3.5e6 m) and a margin; it
/// refuses longer ones. Up to it, the shapes' ray tests are exact to a few float steps of the distances
/// involved.
inline constexpr float cMaxRayLength = 4.0f * cMaxWorldCoordinate;

struct RayCast
{
    Vec3 mOrigin = Vec3::Zero();
    Vec3 mDirection = Vec3::Zero(); ///< Full displacement, not unit length; at most cMaxRayLength for queries
};

/// The largest coordinate of a ray that a shape casts in its local space. Far beyond any ray a world query
/// sends, taken into a body's space and through every level of a compound (CompoundShape::cMaxDepth, each
/// child offset within the world's size), also into a body that has fallen out of the world; and small
/// enough that the ray tests' products of up to three coordinates (1e36) stay below a float's overflow,
/// which is what made up hits.
inline constexpr float cMaxLocalRayCoordinate = 1.0e12f;

/// Whether Shape::CastRay takes the ray: every coordinate of its origin and direction finite and within
/// cMaxLocalRayCoordinate.
inline bool IsCastableRay(const RayCast& inRay)
{
    // One comparison a coordinate: false for NaN as well as for an infinity or a huge value
    return (inRay.mOrigin.cwiseAbs().array() <= cMaxLocalRayCoordinate).all() &&
           (inRay.mDirection.cwiseAbs().array() <= cMaxLocalRayCoordinate).all();
}

/// Identifies a part of a shape: a triangle of a mesh, a cell half of a height field, a compound child...
/// Shapes with one part use 0.
using SubShapeID = uint32_t;

struct RayHit
{
    float mFraction = cLargeFloat; ///< Along RayCast::mDirection, in [0, 1]
    Vec3 mNormal =
        Vec3::Zero(); ///< Unit surface normal at the hit, facing against the ray, same space as the ray
    SubShapeID mSubShape = 0;
};

/// Bits of Triangle::mActiveEdges. An inactive edge is one shared with a neighbour that continues the surface
/// (flat or concave joint): contacts against it must use the face normal so that bodies slide across it.
enum TriangleEdge : uint8_t
{
    cEdge01 = 1u << 0,
    cEdge12 = 1u << 1,
    cEdge20 = 1u << 2,
    cAllEdgesActive = cEdge01 | cEdge12 | cEdge20,
};

struct Triangle
{
    Vec3 mV[3]; ///< Counter-clockwise seen from the front (normal = (v1-v0) x (v2-v0))
    uint8_t mActiveEdges = cAllEdgesActive; ///< TriangleEdge bits
    SubShapeID mSubShape = 0;               ///< Triangle index inside its shape
};

/// Called once per triangle; triangles are in the space the caller asked for.
using TriangleVisitor = FunctionRef<void(const Triangle&)>;

class Shape;
using ShapeRef = std::shared_ptr<const Shape>;

class Shape
{
public:
    explicit Shape(ShapeType inType) : mType(inType) {}
    virtual ~Shape() = default;
    Shape(const Shape&) = delete;
    Shape& operator=(const Shape&) = delete;

    ShapeType GetType() const { return mType; }

    /// True for shapes that GJK/EPA can handle through Support().
    virtual bool IsConvex() const { return false; }

    /// Bounds in shape-local space.
    virtual AABB GetLocalBounds() const = 0;

    /// Bounds in world space for the given transform; shapes override this when they can be tighter than
    /// the transformed local box.
    virtual AABB GetWorldBounds(const Transform& inTransform) const
    {
        return GetLocalBounds().Transformed(inTransform);
    }

    /// Mass properties for a uniform density in kg/m^3. Shapes without volume (meshes, height fields)
    /// return zero mass: they can only be static or kinematic.
    virtual MassProperties GetMassProperties(float inDensity) const = 0;

    /// Closest hit of a local-space ray with fraction < ioHit.mFraction; updates ioHit and returns true on a
    /// hit. A ray starting inside a solid shape hits at fraction 0 (normal = -ray direction). A ray that
    /// IsCastableRay refuses has no hit (WorldQuery's rays all pass: it refuses the others with an error):
    /// the ray tests' maths on a NaN, an infinity or an overflowing square reported hits anywhere.
    bool CastRay(const RayCast& inLocalRay, RayHit& ioHit) const
    {
        return IsCastableRay(inLocalRay) && CastCheckedRay(inLocalRay, ioHit);
    }

    /// Visits every triangle of the surface that may overlap inLocalBox (local space). Convex primitives
    /// visit a tessellation (spheres and capsules with a fixed resolution). Visiting extra triangles is
    /// allowed; missing one that overlaps is not.
    virtual void VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const = 0;

    /// World-space triangles (3 vertices each, appended to outVertices) of this shape at inTransform that may
    /// overlap inWorldBox: the navmesh collects geometry with this.
    void CollectTriangles(const AABB& inWorldBox, const Transform& inTransform,
                          std::vector<Vec3>& outVertices) const;

protected:
    /// CastRay for a ray that IsCastableRay accepts.
    virtual bool CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const = 0;

private:
    ShapeType mType;
};

/// The face of a convex shape that best supports a direction: up to cMaxVertices points (local space) in
/// counter-clockwise order seen from outside. One point for round shapes, two for an edge.
struct SupportingFace
{
    static constexpr int cMaxVertices = 32;
    int mCount = 0;
    Vec3 mVertices[cMaxVertices];
};

/// A convex shape, usable by GJK and EPA.
class ConvexShape : public Shape
{
public:
    using Shape::Shape;

    bool IsConvex() const override { return true; }

    /// The point of the shape (local space) furthest along inDirection (need not be normalised, non-zero).
    virtual Vec3 GetSupport(const Vec3& inDirection) const = 0;

    /// The face whose outward normal is closest to inDirection (local space); used to build contact
    /// manifolds by clipping. The default gives the single support point.
    virtual void GetSupportingFace(const Vec3& inDirection, SupportingFace& outFace) const
    {
        outFace.mCount = 1;
        outFace.mVertices[0] = GetSupport(inDirection);
    }
};

/// Geometry helpers shared by the shape implementations (and usable by queries); pure functions.
namespace ShapeHelpers
{

/// Unit vector along inV, or inFallback when inV is zero or not finite; never NaN.
Vec3 SafeNormalized(const Vec3& inV, const Vec3& inFallback);

/// Records a hit at fraction 0 for a ray that starts inside a solid shape (normal = -ray direction).
/// Returns false when ioHit already holds a hit at fraction 0.
bool ReportStartInside(const RayCast& inRay, RayHit& ioHit);

/// Two-sided intersection of the segment inRay with triangle (inV0, inV1, inV2): the fraction in [0, 1],
/// or cLargeFloat on a miss (including rays parallel to the triangle and degenerate triangles).
float RayTriangleFraction(const RayCast& inRay, const Vec3& inV0, const Vec3& inV1, const Vec3& inV2);

/// Unit normal of a triangle facing against the ray direction (for two-sided hits).
Vec3 TriangleNormalFacing(const Vec3& inV0, const Vec3& inV1, const Vec3& inV2, const Vec3& inRayDirection);

/// True when an edge shared by a triangle (normal inNormal, inEdgePoint on the edge) and one neighbour
/// (normal inNeighbourNormal, inNeighbourApex = its vertex not on the edge) must stay active: the joint is
/// convex and not flat (the normals' cosine <= inCosThreshold). Flat and concave joints are internal
/// (inactive). The normals may have any finite, non-zero length (an edge cross product will do).
bool IsEdgeActive(const Vec3& inNormal, const Vec3& inEdgePoint, const Vec3& inNeighbourNormal,
                  const Vec3& inNeighbourApex, float inCosThreshold);

/// Bounds of a triangle.
AABB TriangleBounds(const Vec3& inV0, const Vec3& inV1, const Vec3& inV2);

} // namespace ShapeHelpers

} // namespace cairn::physics
