#include "narrowphase/CollideSphereCapsule.h"

#include "narrowphase/ClosestPoints.h"
#include "narrowphase/CollideSphereSphere.h"

namespace cairn::physics
{

bool CollideSphereCapsule(const SphereShape& inA, const Transform& inTransformA, const CapsuleShape& inB,
                          const Transform& inTransformB, const CollideSettings& inSettings,
                          ContactManifold& outManifold)
{
    const Vec3 axis = inTransformB.RotateVector(Vec3(0.0f, inB.GetHalfHeight(), 0.0f));
    float t;
    const Vec3 onSegment = ClosestPointOnSegment(inTransformA.mPosition, inTransformB.mPosition - axis,
                                                 inTransformB.mPosition + axis, t);
    // A centre on the segment: push out perpendicular to the axis, the shortest way out of the capsule
    const Vec3 fallback = AnyPerpendicular(axis.squaredNorm() > 0.0f ? Vec3(axis) : Vec3(Vec3::UnitY()));
    return CollideBalls(inTransformA.mPosition, inA.GetRadius(), onSegment, inB.GetRadius(), fallback,
                        inSettings.mMaxSeparation, outManifold);
}

} // namespace cairn::physics
