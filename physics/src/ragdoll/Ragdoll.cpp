#include "cairn/physics/ragdoll/Ragdoll.h"

#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/narrowphase/CollideShapes.h"

#include <string>

namespace cairn::physics
{

namespace
{
/// The group table: every pair of parts collides except, if asked, each part with its parent.
std::shared_ptr<GroupFilterTable> MakeGroupTable(const RagdollSettings& inSettings)
{
    auto table = std::make_shared<GroupFilterTable>(uint32_t(inSettings.mParts.size()));
    if (inSettings.mDisableParentChildCollisions)
        for (size_t part = 1; part < inSettings.mParts.size(); ++part)
            table->DisableCollision(uint32_t(part), uint32_t(inSettings.mParts[part].mParent));
    for (const auto& [a, b] : inSettings.mNoCollisionPairs) // Out of range: ignored by the table
        table->DisableCollision(a, b);
    return table;
}

Status CheckParents(const RagdollSettings& inSettings)
{
    const std::vector<RagdollPart>& parts = inSettings.mParts;
    if (parts.empty() || parts.size() > RagdollSettings::cMaxParts)
        return MakeError(ErrorCode::InvalidArgument, "a ragdoll has 1 to 256 parts");
    if (parts[0].mParent != -1)
        return MakeError(ErrorCode::InvalidArgument, "a ragdoll's first part is its root (parent -1)");
    for (size_t part = 1; part < parts.size(); ++part)
        if (!(parts[part].mParent >= 0 && size_t(parts[part].mParent) < part))
            return MakeError(ErrorCode::InvalidArgument,
                             "ragdoll part " + std::to_string(part) + ": its parent must be an earlier part");
    return Status::Ok();
}
} // namespace

void RagdollSettings::DisableCollisionsOfTouchingParts(float inMinSeparation)
{
    CollideSettings settings;
    settings.mMaxSeparation = inMinSeparation;
    for (size_t a = 0; a < mParts.size(); ++a)
        for (size_t b = a + 1; b < mParts.size(); ++b)
        {
            const BodyCreationSettings& bodyA = mParts[a].mBody;
            const BodyCreationSettings& bodyB = mParts[b].mBody;
            if (bodyA.mShape == nullptr || bodyB.mShape == nullptr) continue; // Create refuses it anyway
            bool touching = false;
            CollideShapes(*bodyA.mShape, {bodyA.mPosition, bodyA.mRotation}, *bodyB.mShape,
                          {bodyB.mPosition, bodyB.mRotation}, settings,
                          [&](const ContactManifold&) { touching = true; });
            if (touching) mNoCollisionPairs.push_back({uint32_t(a), uint32_t(b)});
        }
}

Result<Ragdoll> Ragdoll::Create(PhysicsSystem& ioSystem, const RagdollSettings& inSettings,
                                const Vec3& inPosition, const Quat& inRotation, uint32_t inGroupID,
                                Activation inActivation)
{
    if (Status parents = CheckParents(inSettings); !parents) return parents.GetError();
    if (!IsValidWorldPosition(inPosition) || !IsValidRotation(inRotation))
        return MakeError(ErrorCode::InvalidArgument, "a ragdoll's pose is NaN, infinite or beyond the world");
    if (inGroupID == CollisionGroup::cNoGroup)
        return MakeError(ErrorCode::InvalidArgument, "a ragdoll needs a collision group of its own");
    const Quat rotation = inRotation.normalized();
    const std::shared_ptr<const GroupFilterTable> table = MakeGroupTable(inSettings);
    BodyInterface& bodies = ioSystem.GetBodyInterface();
    ConstraintInterface& joints = ioSystem.GetConstraintInterface();
    Ragdoll ragdoll;
    bool added = false;
    // Takes back what was made when a later step fails: the caller gets an error and no half ragdoll
    auto undo = [&](const Error& inError) -> Result<Ragdoll>
    {
        for (const ConstraintID& joint : ragdoll.mJoints)
            (void)joints.Remove(joint);
        for (const BodyID& body : ragdoll.mBodies)
        {
            if (added) (void)bodies.RemoveBody(body);
            (void)bodies.DestroyBody(body);
        }
        return inError;
    };

    ragdoll.mBodies.reserve(inSettings.mParts.size());
    for (size_t part = 0; part < inSettings.mParts.size(); ++part)
    {
        BodyCreationSettings settings = inSettings.mParts[part].mBody;
        settings.mPosition = rotation * settings.mPosition + inPosition;
        settings.mRotation = (rotation * settings.mRotation).normalized();
        settings.mLinearVelocity = rotation * settings.mLinearVelocity;
        settings.mAngularVelocity = rotation * settings.mAngularVelocity;
        settings.mCollisionGroup = {table, inGroupID, uint32_t(part)};
        Result<BodyID> body = bodies.CreateBody(settings);
        if (!body)
            return undo({body.GetError().mCode,
                         "ragdoll part " + std::to_string(part) + ": " + body.GetError().mMessage});
        ragdoll.mBodies.push_back(body.Value());
    }
    // One batch: the broad phase prepares the parts off to the side and links them in one step
    Result<BodyInterface::AddBatch> batch = bodies.AddBodiesPrepare(ragdoll.mBodies);
    if (!batch) return undo(batch.GetError());
    if (Status finalized = bodies.AddBodiesFinalize(batch.Value(), inActivation); !finalized)
    {
        (void)bodies.AddBodiesAbort(batch.Value());
        return undo(finalized.GetError());
    }
    added = true;

    ragdoll.mJoints.reserve(inSettings.mParts.size() - 1);
    for (size_t part = 1; part < inSettings.mParts.size(); ++part)
    {
        SwingTwistConstraintSettings joint = inSettings.mParts[part].mJoint;
        joint.mBodyA = ragdoll.mBodies[size_t(inSettings.mParts[part].mParent)];
        joint.mBodyB = ragdoll.mBodies[part];
        joint.mPoint = rotation * joint.mPoint + inPosition;
        joint.mTwistAxis = rotation * joint.mTwistAxis;
        joint.mPlaneAxis = rotation * joint.mPlaneAxis;
        Result<ConstraintID> id = joints.AddSwingTwist(joint);
        if (!id)
            return undo({id.GetError().mCode,
                         "ragdoll joint of part " + std::to_string(part) + ": " + id.GetError().mMessage});
        ragdoll.mJoints.push_back(id.Value());
    }
    return ragdoll;
}

Status Ragdoll::Destroy(PhysicsSystem& ioSystem)
{
    Status first = Status::Ok();
    auto keep = [&](Status inStatus)
    {
        if (first && !inStatus) first = inStatus;
    };
    for (const ConstraintID& joint : mJoints)
        keep(ioSystem.GetConstraintInterface().Remove(joint));
    for (const BodyID& body : mBodies)
    {
        keep(ioSystem.GetBodyInterface().RemoveBody(body));
        keep(ioSystem.GetBodyInterface().DestroyBody(body));
    }
    mJoints.clear();
    mBodies.clear();
    return first;
}

} // namespace cairn::physics
