#include "Integration.h"

#include "step/StepContext.h"

#include <algorithm>
#include <cmath>

namespace cairn::physics
{

namespace
{
Vec3 ClampLength(const Vec3& inV, float inMax)
{
    const float lengthSq = inV.squaredNorm();
    if (!(lengthSq > inMax * inMax)) return inV;
    if (std::isfinite(lengthSq)) return inV * (inMax / std::sqrt(lengthSq));
    // Finite but too long to square (a huge force on a light body): scale it down first, the direction is
    // all that is kept
    const Vec3 scaled = inV / inV.cwiseAbs().maxCoeff();
    return scaled * (inMax / scaled.norm());
}
} // namespace

void Integration::IntegrateVelocities(const StepContext& inContext, std::span<const uint32_t> inBodies)
{
    const float deltaTime = inContext.mDeltaTime;
    for (uint32_t index : inBodies)
    {
        Body& body = inContext.BodyAt(index);
        if (!body.IsDynamic())
        {
            // Kinematic bodies move as set, within the same limits (a limit is what keeps every speed finite)
            body.mLinearVelocity = ClampLength(body.mLinearVelocity, body.mMaxLinearVelocity);
            body.mAngularVelocity = ClampLength(body.mAngularVelocity, body.mMaxAngularVelocity);
            continue;
        }
        // Kept for the narrow phase: every constraint of the body needs it, and the rotation stays until the
        // solver
        mInverseInertia[body.GetActiveIndex()] = body.GetInverseInertiaWorld();
        // Symplectic Euler, velocity half: v(t + dt) = v(t) + dt * a(t); positions follow with the new
        // velocity. The change is the one the bounces read (ForceVelocityChangeOf): one formula for both
        const VelocityChange change = ForceVelocityChangeOf(inContext, body);
        body.mLinearVelocity += change.mLinear;
        body.mAngularVelocity += change.mAngular;
        body.mLinearVelocity *= std::max(0.0f, 1.0f - body.mLinearDamping * deltaTime);
        body.mAngularVelocity *= std::max(0.0f, 1.0f - body.mAngularDamping * deltaTime);
        body.mLinearVelocity = ClampLength(body.mLinearVelocity, body.mMaxLinearVelocity);
        body.mAngularVelocity = ClampLength(body.mAngularVelocity, body.mMaxAngularVelocity);
    }
}

Mat3 Integration::InverseInertiaOf(const Body& inBody) const
{
    if (!inBody.IsDynamic()) return Mat3::Zero();
    // A body still asleep (woken by this contact at the merge) had no forces applied: nothing kept for it
    return inBody.IsActive() ? mInverseInertia[inBody.GetActiveIndex()] : inBody.GetInverseInertiaWorld();
}

VelocityChange Integration::ForceVelocityChangeOf(const StepContext& inContext, const Body& inBody) const
{
    if (!inBody.IsDynamic() || !inBody.IsActive()) return {Vec3::Zero(), Vec3::Zero()};
    const float deltaTime = inContext.mDeltaTime;
    return {deltaTime *
                (inBody.mGravityFactor * inContext.mSettings.mGravity + inBody.mInvMass * inBody.mForce),
            deltaTime * (mInverseInertia[inBody.GetActiveIndex()] * inBody.mTorque)};
}

void Integration::IntegratePositions(Body& ioBody, float inDeltaTime)
{
    // Symplectic Euler, position half: uses the velocity after gravity and contacts
    ioBody.mPosition += inDeltaTime * ioBody.mLinearVelocity;
    ioBody.mRotation = IntegrateRotation(ioBody.mRotation, inDeltaTime * ioBody.mAngularVelocity);
}

void Integration::CorrectPose(Body& ioBody, const Vec3& inTranslation, const Vec3& inRotation)
{
    ioBody.mPosition += inTranslation;
    ioBody.mRotation = IntegrateRotation(ioBody.mRotation, inRotation);
}

} // namespace cairn::physics
