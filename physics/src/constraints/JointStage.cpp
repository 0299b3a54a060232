#include "constraints/JointStage.h"

#include "body/Integration.h"
#include "cairn/physics/solver/SolverSettings.h"
#include "step/StepContext.h"

namespace cairn::physics
{

namespace
{
SolverBody BlockOf(const Body* inBody)
{
    // Not dynamic: the world and static bodies stand still, a kinematic body moves as it was told
    SolverBody block;
    block.mLinearVelocity = inBody != nullptr ? inBody->GetLinearVelocity() : Vec3::Zero();
    block.mInverseMass = 0.0f;
    block.mAngularVelocity = inBody != nullptr ? inBody->GetAngularVelocity() : Vec3::Zero();
    block.mPadding = 0.0f;
    return block;
}

bool IsActiveDynamic(const Body* inBody)
{
    return inBody != nullptr && inBody->IsDynamic() && inBody->IsActive();
}
} // namespace

void JointStage::BeginStep(const StepContext& inContext, ConstraintManager& ioManager)
{
    mContext = &inContext;
    mStepJoints.clear();
    std::vector<Joint>& joints = ioManager.GetJoints();
    if (ioManager.GetNumInUse() == 0) return;
    auto bodyOf = [&](const BodyID& inID) -> Body*
    {
        if (inID.IsInvalid()) return nullptr;
        Body* body = inContext.mBodies.TryGetBody(inID);
        return body != nullptr && body->IsInWorld() ? body : nullptr;
    };
    // A sleeping dynamic body jointed to an active one wakes (and then its own jointed sleepers): in slot
    // order, again until nothing wakes, so the same bodies wake on every run
    for (bool woke = true; woke;)
    {
        woke = false;
        for (Joint& joint : joints)
        {
            if (!joint.mInUse || !joint.mEnabled) continue;
            Body* a = bodyOf(joint.mBodyA);
            Body* b = bodyOf(joint.mBodyB);
            if ((!joint.mBodyA.IsInvalid() && a == nullptr) || (!joint.mBodyB.IsInvalid() && b == nullptr))
                continue; // A side gone or out of the world: the joint waits
            for (auto [sleeper, other] : {std::pair(a, b), std::pair(b, a)})
                if (sleeper != nullptr && sleeper->IsDynamic() && !sleeper->IsActive() && other != nullptr &&
                    other->IsActive())
                {
                    inContext.mBodies.ActivateBody(*sleeper);
                    woke |= sleeper->IsActive();
                }
        }
    }
    for (Joint& joint : joints)
    {
        if (!joint.mInUse || !joint.mEnabled) continue;
        Body* a = bodyOf(joint.mBodyA);
        Body* b = bodyOf(joint.mBodyB);
        if ((!joint.mBodyA.IsInvalid() && a == nullptr) || (!joint.mBodyB.IsInvalid() && b == nullptr))
            continue;
        // Solved only with an awake dynamic side; a dynamic side asleep while the other is active cannot be
        // (it woke above), so both dynamic sides are awake here
        if (!IsActiveDynamic(a) && !IsActiveDynamic(b)) continue;
        if ((a != nullptr && a->IsDynamic() && !a->IsActive()) ||
            (b != nullptr && b->IsDynamic() && !b->IsActive()))
            continue; // Could not wake (defensive: ActivateBody refused)
        mStepJoints.push_back(
            {&joint, a, b, BlockOf(a), BlockOf(b), Vec3::Zero(), Vec3::Zero(), false, 0.0f});
    }
}

void JointStage::LinkIslands(const StepContext& inContext)
{
    for (const StepJoint& joint : mStepJoints)
        if (IsActiveDynamic(joint.mA) && IsActiveDynamic(joint.mB))
            inContext.mIslands.Union(joint.mA->GetActiveIndex(), joint.mB->GetActiveIndex());
}

void JointStage::GroupByIsland(const StepContext& inContext)
{
    if (mStepJoints.empty()) return; // HasJoints answers false without the table
    const AtomicUnionFind& islands = inContext.mIslands;
    const uint32_t numIslands = islands.GetNumIslands();
    mJointStart.assign(numIslands + 1, 0);
    mJointIsland.resize(mStepJoints.size());
    for (size_t i = 0; i < mStepJoints.size(); ++i)
    {
        const StepJoint& joint = mStepJoints[i];
        const Body& dynamic = IsActiveDynamic(joint.mA) ? *joint.mA : *joint.mB;
        mJointIsland[i] = islands.GetIsland(dynamic.GetActiveIndex());
        ++mJointStart[mJointIsland[i] + 1];
    }
    for (uint32_t island = 0; island < numIslands; ++island)
        mJointStart[island + 1] += mJointStart[island];
    mIslandJoints.resize(mStepJoints.size());
    std::vector<uint32_t> cursor(mJointStart.begin(), mJointStart.end() - 1);
    for (uint32_t i = 0; i < uint32_t(mStepJoints.size()); ++i) // Slot order within each island
        mIslandJoints[cursor[mJointIsland[i]]++] = i;
}

void JointStage::Prepare(StepJoint& ioJoint)
{
    Joint& joint = *ioJoint.mJoint;
    // Each side's arm (centre of mass to anchor, world space), anchor and masses at its pose now; the world's
    // side: its point, no arm, nothing that moves
    auto side =
        [](const Body* inBody, const Vec3& inLocal, Vec3& outArm, Vec3& outAnchor, JointBodyMass& outMass)
    {
        outArm = inBody != nullptr ? Vec3(inBody->GetRotation() * inLocal) : Vec3::Zero();
        outAnchor = inBody != nullptr ? Vec3(inBody->GetCenterOfMassPosition() + outArm) : inLocal;
        outMass = {};
        if (inBody != nullptr && inBody->IsDynamic())
            outMass = {inBody->GetInverseMass(), inBody->GetInverseInertiaWorld()};
    };
    Vec3 armA, armB, anchorA, anchorB;
    JointBodyMass massA, massB;
    side(ioJoint.mA, joint.mLocalA, armA, anchorA, massA);
    side(ioJoint.mB, joint.mLocalB, armB, anchorB, massB);
    ioJoint.mAnchorA = anchorA;
    ioJoint.mAnchorB = anchorB;
    switch (joint.mType)
    {
    case JointType::Point:
        joint.mPart.Prepare(armA, massA, armB, massB);
        break;
    case JointType::Fixed:
        joint.mPart.Prepare(armA, massA, armB, massB);
        joint.mRotationPart.Prepare(massA, massB);
        break;
    case JointType::Hinge:
    {
        joint.mPart.Prepare(armA, massA, armB, massB);
        const Quat rotationA = ioJoint.mA != nullptr ? ioJoint.mA->GetRotation() : Quat::Identity();
        const Quat rotationB = ioJoint.mB != nullptr ? ioJoint.mB->GetRotation() : Quat::Identity();
        const Vec3 axisA = rotationA * joint.mLocalAxisA, axisB = rotationB * joint.mLocalAxisB;
        joint.mHingePart.Prepare(massA, massB, axisA, axisB);
        // B's angle about A's axis from where it was at creation: the turn from A's normal to B's
        const Vec3 normalA = rotationA * joint.mLocalNormalA, normalB = rotationB * joint.mLocalNormalB;
        const float angle = std::atan2(normalA.cross(normalB).dot(axisA), normalA.dot(normalB));
        constexpr float cPi = 3.14159265358979f;
        const bool limited = joint.mLimitsMin > -cPi || joint.mLimitsMax < cPi;
        if (limited && joint.mLimitsMin == joint.mLimitsMax)
            joint.mLimitPart.Prepare(massA, massB, axisA, 0.0f, -cLargeFloat, cLargeFloat,
                                     AxisJointPart::Side::Both, angle - joint.mLimitsMin);
        else if (limited && angle < joint.mLimitsMin)
            joint.mLimitPart.Prepare(massA, massB, axisA, 0.0f, -cLargeFloat, cLargeFloat,
                                     AxisJointPart::Side::Positive, angle - joint.mLimitsMin);
        else if (limited && angle > joint.mLimitsMax)
            joint.mLimitPart.Prepare(massA, massB, axisA, 0.0f, -cLargeFloat, cLargeFloat,
                                     AxisJointPart::Side::Negative, angle - joint.mLimitsMax);
        else
            joint.mLimitPart.Deactivate();
        // The motor, or the friction while it is off: a spin towards the target, within its torque this step
        const float dt = mContext->mDeltaTime;
        if (joint.mMotorMode == MotorMode::Velocity && joint.mMaxMotorTorque > 0.0f)
            joint.mMotorPart.Prepare(massA, massB, axisA, joint.mTargetAngularVelocity,
                                     -joint.mMaxMotorTorque * dt, joint.mMaxMotorTorque * dt,
                                     AxisJointPart::Side::Both, 0.0f);
        else if (joint.mMotorMode == MotorMode::Off && joint.mMaxFrictionTorque > 0.0f)
            joint.mMotorPart.Prepare(massA, massB, axisA, 0.0f, -joint.mMaxFrictionTorque * dt,
                                     joint.mMaxFrictionTorque * dt, AxisJointPart::Side::Both, 0.0f);
        else
            joint.mMotorPart.Deactivate();
        break;
    }
    case JointType::Distance:
    {
        const Vec3 between = anchorB - anchorA;
        const float length = between.norm();
        // Points on each other: any direction will do to push them apart (a rod of length 0 holds them)
        const Vec3 axis = length > 1.0e-6f ? Vec3(between / length) : Vec3::UnitX();
        AxisJointPart::Side rowSide = AxisJointPart::Side::Both;
        float error = 0.0f;
        if (joint.mMinDistance == joint.mMaxDistance)
            error = length - joint.mMinDistance;
        else if (length < joint.mMinDistance)
        {
            error = length - joint.mMinDistance;
            rowSide = AxisJointPart::Side::Positive;
        }
        else if (length > joint.mMaxDistance)
        {
            error = length - joint.mMaxDistance;
            rowSide = AxisJointPart::Side::Negative;
        }
        else
        {
            // Within its limits: no row this step (and no impulse to warm-start the next one from)
            ioJoint.mRowActive = false;
            joint.mAxisPart.ResetImpulse();
            break;
        }
        ioJoint.mRowActive = true;
        ioJoint.mError = error;
        joint.mAxisPart.Prepare(armA, massA, armB, massB, axis, error, rowSide, joint.mSpring.mFrequency,
                                joint.mSpring.mDamping, mContext->mDeltaTime);
        break;
    }
    }
}

SolverBody& JointStage::BlockA(StepJoint& ioJoint, std::span<SolverBody> ioBodies) const
{
    return IsActiveDynamic(ioJoint.mA) ? ioBodies[ioJoint.mA->GetActiveIndex()] : ioJoint.mBlockA;
}

SolverBody& JointStage::BlockB(StepJoint& ioJoint, std::span<SolverBody> ioBodies) const
{
    return IsActiveDynamic(ioJoint.mB) ? ioBodies[ioJoint.mB->GetActiveIndex()] : ioJoint.mBlockB;
}

void JointStage::WarmStart(uint32_t inIsland, std::span<SolverBody> ioBodies)
{
    for (uint32_t j = mJointStart[inIsland]; j < mJointStart[inIsland + 1]; ++j)
    {
        StepJoint& joint = mStepJoints[mIslandJoints[j]];
        Prepare(joint);
        if (joint.mJoint->mType == JointType::Fixed)
            joint.mJoint->mRotationPart.WarmStart(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
        if (joint.mJoint->mType == JointType::Hinge)
        {
            joint.mJoint->mMotorPart.WarmStart(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
            joint.mJoint->mLimitPart.WarmStart(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
            joint.mJoint->mHingePart.WarmStart(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
        }
        if (joint.mJoint->mType != JointType::Distance)
            joint.mJoint->mPart.WarmStart(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
        else if (joint.mRowActive)
            joint.mJoint->mAxisPart.WarmStart(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
    }
}

void JointStage::SolveVelocities(uint32_t inIsland, std::span<SolverBody> ioBodies)
{
    for (uint32_t j = mJointStart[inIsland]; j < mJointStart[inIsland + 1]; ++j)
    {
        StepJoint& joint = mStepJoints[mIslandJoints[j]];
        // A fixed joint's rotation first: the point's rows then see the bodies turning together
        if (joint.mJoint->mType == JointType::Fixed)
            joint.mJoint->mRotationPart.SolveVelocity(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
        // A hinge's motor (or friction) first, then its limit, which has the last word on the spin about the
        // axis, then the axis and the point
        if (joint.mJoint->mType == JointType::Hinge)
        {
            joint.mJoint->mMotorPart.SolveVelocity(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
            joint.mJoint->mLimitPart.SolveVelocity(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
            joint.mJoint->mHingePart.SolveVelocity(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
        }
        if (joint.mJoint->mType != JointType::Distance)
            joint.mJoint->mPart.SolveVelocity(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
        else if (joint.mRowActive)
            joint.mJoint->mAxisPart.SolveVelocity(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
    }
}

void JointStage::SolvePositions(uint32_t inIsland, const SolverSettings& inSettings)
{
    for (uint32_t j = mJointStart[inIsland]; j < mJointStart[inIsland + 1]; ++j)
    {
        StepJoint& joint = mStepJoints[mIslandJoints[j]];
        // The rows again at the integrated poses (the arms turned with their bodies), then the part of the
        // error the position iterations take out
        Prepare(joint);
        const Joint& data = *joint.mJoint;
        if (data.mType == JointType::Fixed)
        {
            const Quat rotationA = joint.mA != nullptr ? joint.mA->GetRotation() : Quat::Identity();
            const Quat rotationB = joint.mB != nullptr ? joint.mB->GetRotation() : Quat::Identity();
            const PointJointPart::PoseCorrection turn = data.mRotationPart.CorrectPositions(
                RotationJointPart::RotationError(rotationA, rotationB, data.mRelativeRotation),
                inSettings.mBaumgarte);
            if (joint.mA != nullptr && joint.mA->IsDynamic())
                Integration::CorrectPose(*joint.mA, Vec3::Zero(), turn.mRotationA);
            if (joint.mB != nullptr && joint.mB->IsDynamic())
                Integration::CorrectPose(*joint.mB, Vec3::Zero(), turn.mRotationB);
            Prepare(joint); // The anchors where the turn put them
        }
        if (data.mType == JointType::Hinge)
        {
            for (const PointJointPart::PoseCorrection& turn :
                 {data.mHingePart.CorrectPositions(inSettings.mBaumgarte),
                  data.mLimitPart.CorrectPositions(inSettings.mBaumgarte)})
            {
                if (joint.mA != nullptr && joint.mA->IsDynamic())
                    Integration::CorrectPose(*joint.mA, Vec3::Zero(), turn.mRotationA);
                if (joint.mB != nullptr && joint.mB->IsDynamic())
                    Integration::CorrectPose(*joint.mB, Vec3::Zero(), turn.mRotationB);
            }
            Prepare(joint); // The anchors where the turns put them
        }
        PointJointPart::PoseCorrection correction;
        if (data.mType != JointType::Distance)
            correction = data.mPart.CorrectPositions(joint.mAnchorA, joint.mAnchorB, inSettings.mBaumgarte);
        else if (joint.mRowActive)
            correction = data.mAxisPart.CorrectPositions(joint.mError, inSettings.mBaumgarte);
        if (joint.mA != nullptr && joint.mA->IsDynamic())
            Integration::CorrectPose(*joint.mA, correction.mTranslationA, correction.mRotationA);
        if (joint.mB != nullptr && joint.mB->IsDynamic())
            Integration::CorrectPose(*joint.mB, correction.mTranslationB, correction.mRotationB);
    }
}

} // namespace cairn::physics
