#pragma once

// Sphere against sphere, plus the "two balls" helper that the sphere-capsule and capsule-capsule routines
// reduce to once they know their closest core points.

#include "cairn/physics/narrowphase/CollideShapes.h"
#include "cairn/physics/shapes/SphereShape.h"

namespace cairn::physics
{

/// Contact between ball (inCenterA, inRadiusA) and ball (inCenterB, inRadiusB) as a one-point manifold.
/// inFallbackNormal (unit, A towards B) is used when the centres coincide. Returns false beyond
/// inMaxSeparation.
bool CollideBalls(const Vec3& inCenterA, float inRadiusA, const Vec3& inCenterB, float inRadiusB,
                  const Vec3& inFallbackNormal, float inMaxSeparation, ContactManifold& outManifold);

/// Sphere A against sphere B. Returns false when further apart than inSettings.mMaxSeparation.
bool CollideSphereSphere(const SphereShape& inA, const Transform& inTransformA, const SphereShape& inB,
                         const Transform& inTransformB, const CollideSettings& inSettings,
                         ContactManifold& outManifold);

} // namespace cairn::physics
