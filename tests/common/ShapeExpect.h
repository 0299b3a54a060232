#pragma once

// What the shape and narrow-phase tests share: a pose from a place and a turn, a vector's expectation with
// the vectors in its message, a pair's manifolds as a list, and a manifold's deepest point.

#include "cairn/physics/math/Math.h"
#include "cairn/physics/math/Transform.h"
#include "cairn/physics/narrowphase/CollideShapes.h"
#include "cairn/physics/narrowphase/ContactManifold.h"
#include "narrowphase/FaceClipping.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <vector>

namespace cairn::test
{

/// The analytic cases' tolerance: float rounding of a few operations on values near 1
constexpr float cEps = 1.0e-5f;

inline physics::Transform At(const physics::Vec3& inPosition,
                             const physics::Quat& inRotation = physics::Quat::Identity())
{
    return {inPosition, inRotation};
}

inline void ExpectVec(const physics::Vec3& inActual, const physics::Vec3& inExpected,
                      float inTolerance = cEps)
{
    EXPECT_LT((inActual - inExpected).norm(), inTolerance)
        << "actual (" << inActual.transpose() << ") expected (" << inExpected.transpose() << ")";
}

/// Every manifold CollideShapes reports for the pair, in its order; the count it returns must be theirs.
inline std::vector<physics::ContactManifold>
Collide(const physics::Shape& inA, const physics::Transform& inTA, const physics::Shape& inB,
        const physics::Transform& inTB, const physics::CollideSettings& inSettings = {})
{
    std::vector<physics::ContactManifold> result;
    const int count =
        physics::CollideShapes(inA, inTA, inB, inTB, inSettings,
                               [&](const physics::ContactManifold& inM) { result.push_back(inM); });
    EXPECT_EQ(count, int(result.size()));
    return result;
}

using physics::MaxPenetration; // The tests read manifolds' depths as the narrow phase does

} // namespace cairn::test
