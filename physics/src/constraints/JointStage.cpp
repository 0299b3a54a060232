#include "constraints/JointStage.h"

#include "body/Integration.h"
#include "cairn/physics/solver/SolverSettings.h"
#include "constraints/JointGeometry.h"
#include "constraints/SwingTwist.h"
#include "step/StepContext.h"
#include "step/StepCosts.h"

#include <algorithm>
#include <atomic>
#include <numbers>
#include <utility>

namespace cairn::physics
{

namespace
{
/// A limit's row starts this near it (m, rad), speculative until reached: a limit met exactly (as the
/// position pass leaves it) keeps its row, so the bodies' speed into it is stopped, not just their place
constexpr float cLinearLimitBand = 0.01f;
constexpr float cAngleLimitBand = 0.02f;

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

/// Whether a swing-twist joint, as its last Prepare found it, is at its cone or its twist's range: a position
/// iteration then turns its bodies and prepares its point rows after the turns (PreparePoint), not before
bool SwingTwistAtALimit(const Joint& inJoint)
{
    return inJoint.mSwingPart.IsActive() || inJoint.mLimitPart.IsActive();
}

bool IsActiveDynamic(const Body* inBody)
{
    return inBody != nullptr && inBody->IsDynamic() && inBody->IsActive();
}

/// A dynamic body asleep with an active one on the joint's other side: it wakes at the step's start
bool IsSleeperJointedToActive(const Body* inSleeper, const Body* inOther)
{
    return inSleeper != nullptr && inSleeper->IsDynamic() && !inSleeper->IsActive() && inOther != nullptr &&
           inOther->IsActive();
}

bool IsBreakable(const Joint& inJoint)
{
    return inJoint.mBreakForce < cLargeFloat || inJoint.mBreakTorque < cLargeFloat;
}

Quat RotationOf(const Body* inBody)
{
    return inBody != nullptr ? inBody->GetRotation() : Quat::Identity(); // The world does not turn
}
} // namespace

void JointStage::BeginStep(const StepContext& inContext, ConstraintManager& ioManager,
                           const Integration& inIntegration)
{
    mContext = &inContext;
    mIntegration = &inIntegration;
    mManager = &ioManager;
    mStepJoints.clear();
    mBreakableJoints.clear();
    std::vector<Joint>& joints = ioManager.GetJoints();
    if (ioManager.GetNumInUse() == 0) return;
    if (TakeJointsOnAllThreads(joints)) return;
    // A sleeping dynamic body jointed to an active one wakes (and then its own jointed sleepers): in slot
    // order, again until nothing wakes, so the same bodies wake on every run. The pass that wakes nothing
    // takes the step's joints (a joint taken before a wake in the same pass may miss a side woken after it:
    // that pass is taken again)
    for (bool woke = true; woke;)
    {
        woke = false;
        mStepJoints.clear();
        mBreakableJoints.clear();
        for (Joint& joint : joints)
        {
            Body *a = nullptr, *b = nullptr;
            Verdict verdict = VerdictOf(joint, a, b);
            if (verdict == Verdict::Wake)
            {
                for (auto [sleeper, other] : {std::pair(a, b), std::pair(b, a)})
                    if (IsSleeperJointedToActive(sleeper, other))
                    {
                        inContext.mBodies.ActivateBody(*sleeper);
                        woke |= sleeper->IsActive();
                    }
                verdict = VerdictOf(joint, a, b); // Wake again if ActivateBody refused (defensive): not taken
            }
            if (verdict != Verdict::Take) continue;
            if (IsBreakable(joint)) mBreakableJoints.push_back(uint32_t(mStepJoints.size()));
            mStepJoints.push_back({&joint, a, b, BlockOf(a), BlockOf(b)}); // The rest as a new joint's
        }
    }
}

JointStage::Verdict JointStage::VerdictOf(const Joint& inJoint, Body*& outA, Body*& outB) const
{
    // A joint's bodies (null: the world); none while a side is gone or out of the world (the joint waits)
    auto bodyOf = [&](const BodyID& inID) -> Body*
    {
        if (inID.IsInvalid()) return nullptr;
        Body* body = mContext->mBodies.TryGetBody(inID);
        return body != nullptr && body->IsInWorld() ? body : nullptr;
    };
    if (!inJoint.mInUse || !inJoint.mEnabled) return Verdict::Skip;
    outA = bodyOf(inJoint.mBodyA);
    outB = bodyOf(inJoint.mBodyB);
    if ((!inJoint.mBodyA.IsInvalid() && outA == nullptr) || (!inJoint.mBodyB.IsInvalid() && outB == nullptr))
        return Verdict::Skip;
    if (IsSleeperJointedToActive(outA, outB) || IsSleeperJointedToActive(outB, outA)) return Verdict::Wake;
    // Solved only with an awake dynamic side. A dynamic side asleep beside an active one was a Wake above
    // (again when ActivateBody refused it), so a joint taken has both dynamic sides awake
    return IsActiveDynamic(outA) || IsActiveDynamic(outB) ? Verdict::Take : Verdict::Skip;
}

bool JointStage::TakeJointsOnAllThreads(std::vector<Joint>& ioJoints)
{
    // Most steps wake nobody: the step's joints are then a function of the joints and their bodies alone,
    // found in chunks on the step's threads, counted first and then written in slot order where the counts
    // put each chunk's (one serial pass over thousands of joints, a miss or two each, was a fifth of a
    // ragdoll pile's serial time). A chunk that finds a body to wake leaves it all to the serial pass, which
    // wakes in slot order
    const StepScheduler& scheduler = mContext->mScheduler;
    const uint32_t grain = scheduler.GrainFor(ioJoints.size(), StepCosts::cJointsTaken); // Both loops' chunks
    const uint32_t numChunks = uint32_t((ioJoints.size() + grain - 1) / grain);
    mChunkCounts.assign(2 * size_t(numChunks), 0u); // Per chunk: joints taken, then breakable ones
    std::atomic<bool> wakes{false};
    auto chunkOf = [&](uint32_t inChunk)
    {
        const size_t first = size_t(inChunk) * grain;
        return std::span<Joint>(ioJoints).subspan(first, std::min<size_t>(grain, ioJoints.size() - first));
    };
    scheduler.ParallelFor(numChunks, 1, grain * StepCosts::cJointsTaken.mItemNanoseconds,
                          [&](uint32_t inBegin, uint32_t inEnd)
                          {
                              for (uint32_t chunk = inBegin; chunk < inEnd; ++chunk)
                                  for (const Joint& joint : chunkOf(chunk))
                                  {
                                      Body *a = nullptr, *b = nullptr;
                                      const Verdict verdict = VerdictOf(joint, a, b);
                                      // Relaxed: read after the loop's ParallelFor returns
                                      if (verdict == Verdict::Wake)
                                          wakes.store(true, std::memory_order_relaxed);
                                      if (verdict != Verdict::Take) continue;
                                      ++mChunkCounts[2 * chunk];
                                      if (IsBreakable(joint)) ++mChunkCounts[2 * chunk + 1];
                                  }
                          });
    if (wakes.load(std::memory_order_relaxed)) return false; // As above
    // Each chunk's first places, in slot order
    uint32_t taken = 0, breakable = 0;
    for (uint32_t chunk = 0; chunk < numChunks; ++chunk)
    {
        taken += std::exchange(mChunkCounts[2 * chunk], taken);
        breakable += std::exchange(mChunkCounts[2 * chunk + 1], breakable);
    }
    mStepJoints.resize(taken);
    mBreakableJoints.resize(breakable);
    scheduler.ParallelFor(
        numChunks, 1, grain * StepCosts::cJointsTaken.mItemNanoseconds,
        [&](uint32_t inBegin, uint32_t inEnd)
        {
            for (uint32_t chunk = inBegin; chunk < inEnd; ++chunk)
            {
                uint32_t place = mChunkCounts[2 * chunk];
                uint32_t breakablePlace = mChunkCounts[2 * chunk + 1];
                for (Joint& joint : chunkOf(chunk))
                {
                    Body *a = nullptr, *b = nullptr;
                    if (VerdictOf(joint, a, b) != Verdict::Take) continue;
                    if (IsBreakable(joint)) mBreakableJoints[breakablePlace++] = place;
                    mStepJoints[place++] = {&joint, a, b, BlockOf(a), BlockOf(b)}; // As above
                }
            }
        });
    return true;
}

void JointStage::LinkIslands(const StepContext& inContext)
{
    // The union-find takes links from any thread, in any order, with the same islands
    inContext.mScheduler.ParallelFor(uint32_t(mStepJoints.size()), StepCosts::cJointLinks,
                                     [&](uint32_t inBegin, uint32_t inEnd)
                                     {
                                         for (uint32_t i = inBegin; i < inEnd; ++i)
                                             if (const StepJoint& joint = mStepJoints[i];
                                                 IsActiveDynamic(joint.mA) && IsActiveDynamic(joint.mB))
                                                 inContext.mIslands.Union(joint.mA->GetActiveIndex(),
                                                                          joint.mB->GetActiveIndex());
                                     });
}

void JointStage::GroupByIsland(const StepContext& inContext)
{
    if (mStepJoints.empty()) return; // GetIslandJoints answers none without the table
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
    mCursor.assign(mJointStart.begin(), mJointStart.end() - 1);
    for (uint32_t i = 0; i < uint32_t(mStepJoints.size()); ++i) // Slot order within each island
        mIslandJoints[mCursor[mJointIsland[i]]++] = i;
}

void JointStage::SideOf(const Body* inBody, const Vec3& inLocal, Rows inRows, Vec3& outArm, Vec3& outAnchor,
                        JointBodyMass& outMass) const
{
    outArm = inBody != nullptr ? Vec3(inBody->GetRotation() * inLocal) : Vec3::Zero();
    outAnchor = inBody != nullptr ? Vec3(inBody->GetCenterOfMassPosition() + outArm) : inLocal;
    outMass = {};
    if (inBody != nullptr && inBody->IsDynamic())
        outMass = {inBody->GetInverseMass(), inRows == Rows::All ? mIntegration->InverseInertiaOf(*inBody)
                                                                 : inBody->GetInverseInertiaWorld()};
}

void JointStage::PreparePoint(StepJoint& ioJoint)
{
    Joint& joint = *ioJoint.mJoint;
    Vec3 armA, armB;
    JointBodyMass massA, massB;
    SideOf(ioJoint.mA, joint.mLocalA, Rows::WithPosition, armA, ioJoint.mAnchorA, massA);
    SideOf(ioJoint.mB, joint.mLocalB, Rows::WithPosition, armB, ioJoint.mAnchorB, massB);
    joint.mPart.Prepare(armA, massA, armB, massB);
}

void JointStage::Prepare(StepJoint& ioJoint, Rows inRows)
{
    Joint& joint = *ioJoint.mJoint;
    Vec3 armA, armB, anchorA, anchorB;
    JointBodyMass massA, massB;
    SideOf(ioJoint.mA, joint.mLocalA, inRows, armA, anchorA, massA);
    SideOf(ioJoint.mB, joint.mLocalB, inRows, armB, anchorB, massB);
    ioJoint.mAnchorA = anchorA;
    ioJoint.mAnchorB = anchorB;
    switch (joint.mType)
    {
    case JointType::Point:
        joint.mPart.Prepare(armA, massA, armB, massB);
        break;
    case JointType::Fixed:
        // A position iteration turns the bodies first and prepares the point after (PreparePoint)
        if (inRows == Rows::All) joint.mPart.Prepare(armA, massA, armB, massB);
        joint.mRotationPart.Prepare(massA, massB);
        break;
    case JointType::Hinge:
    {
        if (inRows == Rows::All) joint.mPart.Prepare(armA, massA, armB, massB); // As the fixed joint's
        const Quat rotationA = RotationOf(ioJoint.mA), rotationB = RotationOf(ioJoint.mB);
        const Vec3 axisA = rotationA * joint.mLocalAxisA, axisB = rotationB * joint.mLocalAxisB;
        joint.mHingePart.Prepare(massA, massB, axisA, axisB);
        const float angle = HingeAngle(joint, rotationA, rotationB);
        constexpr float cPi = std::numbers::pi_v<float>;
        AxisJointPart::Side limitSide;
        float limitError = 0.0f;
        if ((joint.mLimitsMin > -cPi || joint.mLimitsMax < cPi) &&
            AxisJointPart::LimitRow(angle, joint.mLimitsMin, joint.mLimitsMax, cAngleLimitBand, limitSide,
                                    limitError))
            joint.mLimitPart.PrepareLimit(massA, massB, axisA, limitSide, limitError, mContext->mDeltaTime);
        else
            joint.mLimitPart.Deactivate();
        if (inRows == Rows::WithPosition) break;
        // The motor, or the friction while it is off (a spin towards none), within its torque this step
        const MotorSettings& motor = joint.mMotor;
        const float torque = motor.mMode != MotorMode::Off ? motor.mMaxForce : joint.mMaxFriction;
        const float bound = torque * mContext->mDeltaTime;
        if (!(torque > 0.0f))
            joint.mMotorPart.Deactivate();
        else if (motor.mMode == MotorMode::Position)
            joint.mMotorPart.PrepareSpring(massA, massB, axisA, AngleBetween(angle, motor.mTargetPosition),
                                           motor.mSpring.mFrequency, motor.mSpring.mDamping,
                                           mContext->mDeltaTime, -bound, bound);
        else
            joint.mMotorPart.Prepare(massA, massB, axisA,
                                     motor.mMode == MotorMode::Velocity ? motor.mTargetVelocity : 0.0f,
                                     -bound, bound, AxisJointPart::Side::Both, 0.0f);
        break;
    }
    case JointType::Slider:
    {
        joint.mRotationPart.Prepare(massA, massB);
        // The rows act at B's point: A's arm reaches it through the offset u (A turning swings its line and
        // its axis under B's point)
        const Vec3 axis = RotationOf(ioJoint.mA) * joint.mLocalAxisA;
        const Vec3 offset = anchorB - anchorA;
        const Vec3 armAtB = armA + offset;
        joint.mLinePart.Prepare(armAtB, massA, armB, massB, axis, offset);
        // B's place along the axis from where it was at creation, against the limits
        AxisJointPart::Side limitSide;
        float limitError = 0.0f;
        const float place = SliderPlace(joint, anchorA, anchorB, RotationOf(ioJoint.mA));
        ioJoint.mRowActive = AxisJointPart::LimitRow(place, joint.mLimitsMin, joint.mLimitsMax,
                                                     cLinearLimitBand, limitSide, limitError);
        if (ioJoint.mRowActive)
        {
            ioJoint.mError = limitError;
            joint.mAxisPart.Prepare(armAtB, massA, armB, massB, axis, limitError, limitSide, 0.0f, 0.0f,
                                    mContext->mDeltaTime);
        }
        else
            joint.mAxisPart.Deactivate();
        if (inRows == Rows::WithPosition) break;
        const MotorSettings& motor = joint.mMotor;
        const float force = motor.mMode != MotorMode::Off ? motor.mMaxForce : joint.mMaxFriction;
        const float bound = force * mContext->mDeltaTime;
        if (!(force > 0.0f))
            joint.mAxisMotorPart.Deactivate();
        else if (motor.mMode == MotorMode::Position)
            joint.mAxisMotorPart.PrepareSpringMotor(
                armAtB, massA, armB, massB, axis, place - motor.mTargetPosition, motor.mSpring.mFrequency,
                motor.mSpring.mDamping, mContext->mDeltaTime, -bound, bound);
        else
            joint.mAxisMotorPart.PrepareMotor(
                armAtB, massA, armB, massB, axis,
                motor.mMode == MotorMode::Velocity ? motor.mTargetVelocity : 0.0f, -bound, bound);
        break;
    }
    case JointType::SwingTwist:
    {
        const Quat frameA = RotationOf(ioJoint.mA) * joint.mLocalFrameA;
        const Quat frameB = RotationOf(ioJoint.mB) * joint.mLocalFrameB;
        Quat swing, twist;
        SplitSwingTwist(frameA.conjugate() * frameB, swing, twist);
        // The cone: a row along the direction (in A's frame) that takes the swing further out
        Vec3 outwards;
        float swingError = 0.0f;
        if (SwingPastCone(RotationVector(swing), joint.mNormalHalfCone, joint.mPlaneHalfCone, cAngleLimitBand,
                          outwards, swingError))
            joint.mSwingPart.PrepareLimit(massA, massB, frameA * outwards, AxisJointPart::Side::Negative,
                                          swingError, mContext->mDeltaTime);
        else
            joint.mSwingPart.Deactivate();
        // The twist about B's limb axis, within its range
        AxisJointPart::Side twistSide;
        float twistError = 0.0f;
        if (AxisJointPart::LimitRow(TwistAngle(twist), joint.mLimitsMin, joint.mLimitsMax, cAngleLimitBand,
                                    twistSide, twistError))
            joint.mLimitPart.PrepareLimit(massA, massB, frameB * Vec3::UnitX(), twistSide, twistError,
                                          mContext->mDeltaTime);
        else
            joint.mLimitPart.Deactivate();
        if (inRows == Rows::All || !SwingTwistAtALimit(joint)) joint.mPart.Prepare(armA, massA, armB, massB);
        if (inRows == Rows::WithPosition) break;
        joint.mFrictionPart.Prepare(massA, massB, frameA.toRotationMatrix(),
                                    joint.mMaxFriction * mContext->mDeltaTime);
        break;
    }
    case JointType::Distance:
    {
        const Vec3 between = anchorB - anchorA;
        const float length = between.norm();
        // Points on each other: any direction will do to push them apart (a rod of length 0 holds them)
        const Vec3 axis = length > 1.0e-6f ? Vec3(between / length) : Vec3::UnitX();
        AxisJointPart::Side rowSide;
        float error = 0.0f;
        if (!AxisJointPart::LimitRow(length, joint.mMinDistance, joint.mMaxDistance, cLinearLimitBand,
                                     rowSide, error))
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

template <class Visit> void JointStage::VisitVelocityRows(StepJoint& ioJoint, const Visit& inVisit)
{
    Joint& joint = *ioJoint.mJoint;
    switch (joint.mType)
    {
    case JointType::Fixed:
        // The rotation first: the point's rows then see the bodies turning together
        inVisit(joint.mRotationPart);
        inVisit(joint.mPart);
        break;
    case JointType::Hinge:
        // The motor (or friction), then the limit, which has the last word on the spin about the axis, then
        // the axis and the point
        inVisit(joint.mMotorPart);
        inVisit(joint.mLimitPart);
        inVisit(joint.mHingePart);
        inVisit(joint.mPart);
        break;
    case JointType::Slider:
        // As the hinge: the motor (or friction), the limit, then the rows that hold the rest
        inVisit(joint.mAxisMotorPart);
        if (ioJoint.mRowActive) inVisit(joint.mAxisPart);
        inVisit(joint.mRotationPart);
        inVisit(joint.mLinePart);
        break;
    case JointType::SwingTwist:
        // The friction, then the cone and the twist's range, which have the last word on the turn, then the
        // point
        inVisit(joint.mFrictionPart);
        inVisit(joint.mSwingPart);
        inVisit(joint.mLimitPart);
        inVisit(joint.mPart);
        break;
    case JointType::Point:
        inVisit(joint.mPart);
        break;
    case JointType::Distance:
        if (ioJoint.mRowActive) inVisit(joint.mAxisPart);
        break;
    }
}

void JointStage::GetActiveIndices(uint32_t inJoint, uint32_t& outA, uint32_t& outB) const
{
    const StepJoint& joint = mStepJoints[inJoint];
    outA = IsActiveDynamic(joint.mA) ? joint.mA->GetActiveIndex() : UINT32_MAX;
    outB = IsActiveDynamic(joint.mB) ? joint.mB->GetActiveIndex() : UINT32_MAX;
}

void JointStage::WarmStart(std::span<const uint32_t> inJoints, std::span<SolverBody> ioBodies)
{
    for (const uint32_t index : inJoints)
    {
        StepJoint& joint = mStepJoints[index];
        Prepare(joint);
        SolverBody& a = BlockA(joint, ioBodies);
        SolverBody& b = BlockB(joint, ioBodies);
        VisitVelocityRows(joint, [&](auto& ioPart) { ioPart.WarmStart(a, b); });
    }
}

void JointStage::SolveVelocities(std::span<const uint32_t> inJoints, std::span<SolverBody> ioBodies)
{
    for (const uint32_t index : inJoints)
    {
        StepJoint& joint = mStepJoints[index];
        // The blocks once per joint: the rows' writes to them could alias the bodies BlockA reads, so the
        // compiler would look them up again for every row
        SolverBody& a = BlockA(joint, ioBodies);
        SolverBody& b = BlockB(joint, ioBodies);
        VisitVelocityRows(joint, [&](auto& ioPart) { ioPart.SolveVelocity(a, b); });
    }
}

void JointStage::ApplyCorrection(StepJoint& ioJoint, const PointJointPart::PoseCorrection& inCorrection)
{
    // A row with nothing to take out (a limit not reached) leaves the pose as it is: no turn by zero, whose
    // renormalization would cost a quaternion product and move the rotation by a rounding
    auto correct = [](Body* ioBody, const Vec3& inTranslation, const Vec3& inRotation)
    {
        if (ioBody != nullptr && ioBody->IsDynamic() &&
            (inTranslation != Vec3::Zero() || inRotation != Vec3::Zero()))
            Integration::CorrectPose(*ioBody, inTranslation, inRotation);
    };
    correct(ioJoint.mA, inCorrection.mTranslationA, inCorrection.mRotationA);
    correct(ioJoint.mB, inCorrection.mTranslationB, inCorrection.mRotationB);
}

void JointStage::BreakOverloaded()
{
    if (mBreakableJoints.empty()) return;
    const float inverseStep = 1.0f / mContext->mDeltaTime;
    std::vector<Joint>& joints = mManager->GetJoints();
    for (const uint32_t index : mBreakableJoints) // Slot order
    {
        Joint& joint = *mStepJoints[index].mJoint;
        // The impulses this step held the joint with, as forces
        Vec3 linear = Vec3::Zero(), angular = Vec3::Zero();
        switch (joint.mType)
        {
        case JointType::Point:
        case JointType::SwingTwist:
            linear = joint.mPart.GetTotalImpulse();
            break;
        case JointType::Fixed:
            linear = joint.mPart.GetTotalImpulse();
            angular = joint.mRotationPart.GetTotalImpulse();
            break;
        case JointType::Hinge:
            linear = joint.mPart.GetTotalImpulse();
            angular = joint.mHingePart.GetTotalImpulse();
            break;
        case JointType::Slider:
            linear = joint.mLinePart.GetTotalImpulse();
            angular = joint.mRotationPart.GetTotalImpulse();
            break;
        case JointType::Distance:
            linear = Vec3(joint.mAxisPart.GetTotalImpulse(), 0.0f, 0.0f);
            break;
        }
        const float force = linear.norm() * inverseStep, torque = angular.norm() * inverseStep;
        if (!(force > joint.mBreakForce || torque > joint.mBreakTorque)) continue;
        joint.mEnabled = false; // Its bodies are free from the next step on
        const uint32_t slot = uint32_t(&joint - joints.data());
        mManager->GetBroken().push_back({ConstraintID(slot, joint.mSequence), force, torque});
    }
}

void JointStage::SolvePositions(std::span<const uint32_t> inJoints, const SolverSettings& inSettings)
{
    for (const uint32_t index : inJoints)
    {
        StepJoint& joint = mStepJoints[index];
        // The rows again at the integrated poses (the arms turned with their bodies), then the part of the
        // error the position iterations take out
        Prepare(joint, Rows::WithPosition);
        const Joint& data = *joint.mJoint;
        // The turns first (a rotation part's correction moves no centre), then the point or the length at the
        // anchors where they put them
        // (What follows a turn needs only the point's rows again, at the anchors the turn moved: not the
        // whole joint's)
        if (data.mType == JointType::Fixed || data.mType == JointType::Slider)
        {
            ApplyCorrection(joint,
                            data.mRotationPart.CorrectPositions(
                                RotationJointPart::RotationError(RotationOf(joint.mA), RotationOf(joint.mB),
                                                                 data.mRelativeRotation),
                                inSettings.mJointBaumgarte));
            if (data.mType == JointType::Slider)
                Prepare(joint, Rows::WithPosition);
            else
                PreparePoint(joint);
        }
        // A swing-twist within its cone and range has no turn to take out: its point's rows stand
        if (data.mType == JointType::SwingTwist && SwingTwistAtALimit(data))
        {
            ApplyCorrection(joint, data.mSwingPart.CorrectPositions(inSettings.mJointBaumgarte));
            ApplyCorrection(joint, data.mLimitPart.CorrectPositions(inSettings.mJointBaumgarte));
            PreparePoint(joint);
        }
        if (data.mType == JointType::Hinge)
        {
            ApplyCorrection(joint, data.mHingePart.CorrectPositions(inSettings.mJointBaumgarte));
            ApplyCorrection(joint, data.mLimitPart.CorrectPositions(inSettings.mJointBaumgarte));
            PreparePoint(joint);
        }
        if (data.mType == JointType::Slider)
        {
            // Back onto the line, then within the limits at the place that puts it
            ApplyCorrection(joint, data.mLinePart.CorrectPositions(inSettings.mJointBaumgarte));
            Prepare(joint, Rows::WithPosition);
            if (joint.mRowActive)
                ApplyCorrection(joint,
                                data.mAxisPart.CorrectPositions(joint.mError, inSettings.mJointBaumgarte));
        }
        else if (data.mType != JointType::Distance)
            ApplyCorrection(joint, data.mPart.CorrectPositions(joint.mAnchorA, joint.mAnchorB,
                                                               inSettings.mJointBaumgarte));
        else if (joint.mRowActive)
            ApplyCorrection(joint, data.mAxisPart.CorrectPositions(joint.mError, inSettings.mJointBaumgarte));
    }
}

} // namespace cairn::physics
