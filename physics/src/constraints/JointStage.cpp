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
        mStepJoints.push_back({&joint, a, b, BlockOf(a), BlockOf(b)});
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
    auto side = [](const Body* inBody, const Vec3& inLocal, Vec3& outArm, JointBodyMass& outMass)
    {
        outArm = inBody != nullptr ? Vec3(inBody->GetRotation() * inLocal) : Vec3::Zero();
        outMass = {};
        if (inBody != nullptr && inBody->IsDynamic())
            outMass = {inBody->GetInverseMass(), inBody->GetInverseInertiaWorld()};
    };
    Vec3 armA, armB;
    JointBodyMass massA, massB;
    side(ioJoint.mA, joint.mLocalA, armA, massA);
    side(ioJoint.mB, joint.mLocalB, armB, massB);
    joint.mPart.Prepare(armA, massA, armB, massB);
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
        joint.mJoint->mPart.WarmStart(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
    }
}

void JointStage::SolveVelocities(uint32_t inIsland, std::span<SolverBody> ioBodies)
{
    for (uint32_t j = mJointStart[inIsland]; j < mJointStart[inIsland + 1]; ++j)
    {
        StepJoint& joint = mStepJoints[mIslandJoints[j]];
        joint.mJoint->mPart.SolveVelocity(BlockA(joint, ioBodies), BlockB(joint, ioBodies));
    }
}

void JointStage::SolvePositions(uint32_t inIsland, const SolverSettings& inSettings)
{
    for (uint32_t j = mJointStart[inIsland]; j < mJointStart[inIsland + 1]; ++j)
    {
        StepJoint& joint = mStepJoints[mIslandJoints[j]];
        // The rows again at the integrated poses (the arms turned with their bodies), then the part of the
        // gap the position iterations take out
        Prepare(joint);
        const Joint& data = *joint.mJoint;
        auto anchor = [](const Body* inBody, const Vec3& inLocal)
        {
            return inBody != nullptr
                       ? Vec3(inBody->GetCenterOfMassPosition() + inBody->GetRotation() * inLocal)
                       : inLocal;
        };
        const PointJointPart::PoseCorrection correction = data.mPart.CorrectPositions(
            anchor(joint.mA, data.mLocalA), anchor(joint.mB, data.mLocalB), inSettings.mBaumgarte);
        if (joint.mA != nullptr && joint.mA->IsDynamic())
            Integration::CorrectPose(*joint.mA, correction.mTranslationA, correction.mRotationA);
        if (joint.mB != nullptr && joint.mB->IsDynamic())
            Integration::CorrectPose(*joint.mB, correction.mTranslationB, correction.mRotationB);
    }
}

} // namespace cairn::physics
