#pragma once

// The result of colliding two shapes: one contact plane with up to 4 points. Plain value type.

#include "cairn/physics/shapes/Shape.h"

namespace cairn::physics
{

struct ContactPoint
{
    Vec3 mPositionOnA;  ///< World space, on the surface of shape A
    Vec3 mPositionOnB;  ///< World space, on the surface of shape B
    float mPenetration; ///< dot(mPositionOnA - mPositionOnB, mNormal): > 0 overlapping, < 0 separated
                        ///< (speculative)
};

struct ContactManifold
{
    static constexpr int cMaxPoints = 4;

    Vec3 mNormal =
        Vec3::UnitY(); ///< World space unit normal pointing from A towards B (move B along it to separate)
    int mNumPoints = 0;
    ContactPoint mPoints[cMaxPoints];
    SubShapeID mSubShapeA = 0; ///< Which part of A (triangle, compound child...) made this manifold
    SubShapeID mSubShapeB = 0;
};

/// Receives the manifolds of one shape pair (a mesh or compound can give several).
using ManifoldVisitor = FunctionRef<void(const ContactManifold&)>;

} // namespace cairn::physics
