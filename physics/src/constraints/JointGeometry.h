#pragma once

// Where a hinge or a slider is along its free motion, as its limits and motor measure it: the step's rows and
// ConstraintInterface::GetPosition read it the same way.
//
// Threads: any; pure functions of the poses given.

#include "constraints/ConstraintManager.h"

#include <cmath>
#include <numbers>

namespace cairn::physics
{

/// A hinge's angle: B's turn about A's axis from where it was at creation (rad, within [-pi, pi]), for each
/// body's rotation now (the world's: identity).
inline float HingeAngle(const Joint& inJoint, const Quat& inRotationA, const Quat& inRotationB)
{
    // The turn from A's normal to B's, about A's axis
    const Vec3 axisA = inRotationA * inJoint.mLocalAxisA;
    const Vec3 normalA = inRotationA * inJoint.mLocalNormalA, normalB = inRotationB * inJoint.mLocalNormalB;
    return std::atan2(normalA.cross(normalB).dot(axisA), normalA.dot(normalB));
}

/// A slider's place: B's point less A's along A's axis (m, 0 at creation), for the two anchors in world space
/// and A's rotation now.
inline float SliderPlace(const Joint& inJoint, const Vec3& inAnchorA, const Vec3& inAnchorB,
                         const Quat& inRotationA)
{
    return (inAnchorB - inAnchorA).dot(inRotationA * inJoint.mLocalAxisA);
}

/// inAngle less inTarget, the short way round (within [-pi, pi]).
inline float AngleBetween(float inAngle, float inTarget)
{
    return std::remainder(inAngle - inTarget, 2.0f * std::numbers::pi_v<float>);
}

} // namespace cairn::physics
