#include "cairn/physics/body/BodyInterface.h"

#include "body/AddBatchRegistry.h"
#include "cairn/physics/body/BodyLock.h"

#include <cmath>
#include <string>
#include <utility>

namespace cairn::physics
{

namespace
{
Error WrongThread()
{
    return MakeError(ErrorCode::WrongThread,
                     "body interface called inside the physics step or while this thread holds a body lock");
}
Error StaleID()
{
    return MakeError(ErrorCode::InvalidBodyID, "stale or unknown body id");
}
Error OtherWorldsBatch()
{
    return MakeError(ErrorCode::InvalidArgument, "add batch was prepared by another physics system");
}
Error InvalidVector(const char* inWhat)
{
    return MakeError(ErrorCode::InvalidArgument, std::string(inWhat) + " is NaN, infinite or out of range");
}
BroadPhaseBody ToBroadPhase(const Body& inBody)
{
    return {inBody.GetID(), inBody.GetWorldBounds(), inBody.GetObjectLayer()};
}
const char* MotionTypeName(MotionType inType)
{
    switch (inType)
    {
    case MotionType::Static:
        return "static";
    case MotionType::Kinematic:
        return "kinematic";
    case MotionType::Dynamic:
        return "dynamic";
    }
    return "unknown";
}
/// What an OutOfCapacity from the broad phase adds: a pool the world's capacity sizes fills with the nodes
/// of removed bodies too, which only a broad-phase update frees
constexpr const char* cBroadPhaseFullHint =
    " (removed bodies hold broad-phase nodes until the next Update or PhysicsSystem::OptimizeBroadPhase)";
} // namespace

BodyInterface::BodyInterface(BodyManager& ioBodies, BroadPhase& ioBroadPhase, const LayerSetup& inLayers)
    : mBodies(ioBodies), mBroadPhase(ioBroadPhase), mLayers(inLayers),
      mBatches(std::make_shared<AddBatchRegistry>(*this))
{
}

BodyInterface::~BodyInterface()
{
    // The bodies go with the world, so only the broad phase's prepared states need freeing
    for (BroadPhase::AddState state : mBatches->Close())
        mBroadPhase.AddBodiesAbort(state);
}

Result<BodyID> BodyInterface::CreateBody(const BodyCreationSettings& inSettings)
{
    if (!mLayers.IsValid(inSettings.mObjectLayer))
        return MakeError(ErrorCode::InvalidArgument, "object layer " +
                                                         std::to_string(inSettings.mObjectLayer) +
                                                         " is not in the layer setup");
    return mBodies.CreateBody(inSettings);
}

Status BodyInterface::DestroyBody(const BodyID& inID)
{
    AbortDeferredBatches(); // A body of a batch let go inside the step is pending until then
    return mBodies.DestroyBody(inID);
}

Status BodyInterface::AddBody(const BodyID& inID, Activation inActivation)
{
    AbortDeferredBatches();
    BodyLockWrite lock(mBodies, inID);
    if (lock.WasWrongThread()) return WrongThread();
    Body* body = lock.GetBody();
    if (body == nullptr) return StaleID();
    if (body->mInWorld || body->mAddPending)
        return MakeError(ErrorCode::AlreadyAdded, "body is already in the world");
    body->UpdateBounds();
    const BroadPhaseBody entry = ToBroadPhase(*body);
    BroadPhase::AddState state = mBroadPhase.AddBodiesPrepare({&entry, 1});
    if (state == nullptr)
        return MakeError(ErrorCode::OutOfCapacity,
                         std::string("the broad phase has no room for this body") + cBroadPhaseFullHint);
    mBroadPhase.AddBodiesFinalize(state);
    body->mInWorld = true;
    mBodies.PublishPose(*body); // After the broad phase has its bounds: see PublishedPose.h
    mBodies.NotifyChange(BodyChangeKind::Added, *body, AABB::Empty());
    if (inActivation == Activation::Activate) mBodies.ActivateBody(*body);
    return Status::Ok();
}

Result<BodyID> BodyInterface::CreateAndAddBody(const BodyCreationSettings& inSettings,
                                               Activation inActivation)
{
    Result<BodyID> id = CreateBody(inSettings);
    if (!id) return id;
    if (Status added = AddBody(id.Value(), inActivation); !added)
    {
        (void)mBodies.DestroyBody(id.Value());
        return added.GetError();
    }
    return id;
}

Status BodyInterface::RemoveBody(const BodyID& inID)
{
    AABB bounds;
    ObjectLayer layer;
    {
        BodyLockWrite lock(mBodies, inID);
        if (lock.WasWrongThread()) return WrongThread();
        Body* body = lock.GetBody();
        if (body == nullptr) return StaleID();
        if (!body->mInWorld) return MakeError(ErrorCode::NotAdded, "body is not in the world");
        layer = body->GetObjectLayer();
        mBroadPhase.RemoveBodies({&inID, 1});
        mBodies.DeactivateBody(*body);
        body->mInWorld = false;
        mBodies.PublishPose(*body);
        bounds = body->GetWorldBounds();
        mBodies.NotifyChange(BodyChangeKind::Removed, *body, bounds);
    }
    // Bodies resting on the removed one must fall: wake them (with the removed body's lock released, since a
    // thread may hold only one body lock at a time). Only bodies that collide with it can rest on it: a
    // static body's removal skips the other static bodies around it, which made removing n overlapping
    // props cost n^2 (a level's bake unloads every prop it loaded)
    WakeBodiesIn(bounds.Expanded(0.05f), mLayers.GetCollisionMask(layer));
    return Status::Ok();
}

void BodyInterface::WakeBodiesIn(const AABB& inBounds, ObjectLayerMask inLayers)
{
    thread_local std::vector<BodyID> found;
    found.clear();
    mBroadPhase.CollideAABox(inBounds, {inLayers}, [&](BodyID inBody) { found.push_back(inBody); });
    for (const BodyID& id : found)
    {
        {
            // Only dynamic bodies wake. Tell them from the rest under the shard's static mutex, which no
            // reader of bodies takes, instead of write-locking the shard of each static neighbour: a tile's
            // stream-out removes hundreds of bodies, each beside the terrain and other props, and every write
            // lock there made the game's queries of that shard wait (for long when the remover lost its core)
            const StaticBodyLockRead probe(mBodies, id);
            if (!probe.WasNotStatic() || probe.GetNotStaticMotionType() != MotionType::Dynamic) continue;
        }
        BodyLockWrite lock(mBodies, id);
        if (Body* body = lock.GetBody(); body != nullptr && body->IsDynamic() && body->mInWorld)
            mBodies.ActivateBody(*body);
    }
}

Result<BodyInterface::AddBatch> BodyInterface::AddBodiesPrepare(std::span<const BodyID> inIDs)
{
    if (!BodyManager::MayTakeBodyLocks()) return WrongThread();
    AbortDeferredBatches();
    AddBatch batch;
    batch.mBodies.reserve(inIDs.size());
    auto undo = [&]
    {
        for (const BroadPhaseBody& entry : batch.mBodies)
        {
            BodyLockWrite lock(mBodies, entry.mID);
            if (Body* body = lock.GetBody(); body != nullptr) body->mAddPending = false;
        }
    };
    for (const BodyID& id : inIDs)
    {
        BodyLockWrite lock(mBodies, id);
        Body* body = lock.GetBody();
        Error error = StaleID();
        if (body != nullptr && !body->mInWorld && !body->mAddPending)
        {
            // Pending: no other AddBody or batch may take this body until this batch is finalized or aborted
            body->mAddPending = true;
            body->UpdateBounds();
            batch.mBodies.push_back(ToBroadPhase(*body));
            continue;
        }
        if (body != nullptr)
            error = MakeError(ErrorCode::AlreadyAdded, "body is already in the world or in another batch");
        lock.Release();
        undo();
        return error;
    }
    batch.mState = mBroadPhase.AddBodiesPrepare(batch.mBodies);
    if (batch.mState == nullptr)
    {
        undo();
        return MakeError(ErrorCode::OutOfCapacity,
                         std::string("the broad phase has no room for this batch") + cBroadPhaseFullHint);
    }
    batch.mRegistry = mBatches; // First: should Register throw, the batch aborts itself as it goes
    mBatches->Register(batch.mState);
    return batch;
}

Status BodyInterface::AddBodiesFinalize(AddBatch& ioBatch, Activation inActivation)
{
    if (!BodyManager::MayTakeBodyLocks()) return WrongThread();
    if (ioBatch.mState == nullptr)
        return MakeError(ErrorCode::InvalidArgument, "batch was not prepared or was already finalized");
    if (ioBatch.mRegistry != mBatches) return OtherWorldsBatch();
    AbortDeferredBatches();
    mBatches->Unregister(ioBatch.mState);
    mBroadPhase.AddBodiesFinalize(ioBatch.mState);
    ioBatch.mState = nullptr;
    for (const BroadPhaseBody& entry : ioBatch.mBodies)
    {
        BodyLockWrite lock(mBodies, entry.mID);
        Body* body = lock.GetBody();
        // A pending body cannot be destroyed or added elsewhere, so the lookup cannot fail
        assert(body != nullptr && body->mAddPending);
        body->mAddPending = false;
        body->mInWorld = true;
        // Moved since the prepare (a loader placing bodies while the batch waited): the broad phase linked
        // the bounds of the prepare, so it gets the current ones now
        if (body->mBounds.mMin != entry.mBounds.mMin || body->mBounds.mMax != entry.mBounds.mMax)
        {
            const BroadPhaseBody moved = ToBroadPhase(*body);
            mBroadPhase.NotifyBodiesAABBChanged({&moved, 1});
        }
        mBodies.PublishPose(*body);
        mBodies.NotifyChange(BodyChangeKind::Added, *body, AABB::Empty());
        if (inActivation == Activation::Activate) mBodies.ActivateBody(*body);
    }
    ioBatch.mBodies.clear();
    return Status::Ok();
}

Status BodyInterface::AddBodiesAbort(AddBatch& ioBatch)
{
    if (ioBatch.mState == nullptr && ioBatch.mBodies.empty())
        return Status::Ok(); // Finished: nothing to free
    // Refused whole: a body lock this thread could not take would leave its body pending for good
    if (!BodyManager::MayTakeBodyLocks()) return WrongThread();
    if (ioBatch.mRegistry != mBatches) return OtherWorldsBatch();
    AbortDeferredBatches();
    AbortBatchParts(std::exchange(ioBatch.mState, nullptr), ioBatch.mBodies);
    ioBatch.mBodies.clear();
    return Status::Ok();
}

void BodyInterface::AbortBatchParts(BroadPhase::AddState inState, const std::vector<BroadPhaseBody>& inBodies)
{
    if (inState != nullptr)
    {
        mBatches->Unregister(inState);
        mBroadPhase.AddBodiesAbort(inState);
    }
    for (const BroadPhaseBody& entry : inBodies)
    {
        BodyLockWrite lock(mBodies, entry.mID);
        if (Body* body = lock.GetBody(); body != nullptr) body->mAddPending = false;
    }
}

void BodyInterface::AbortLetGo(AddBatch& ioBatch)
{
    if (!BodyManager::MayTakeBodyLocks())
        mBatches->Defer({std::exchange(ioBatch.mState, nullptr), std::move(ioBatch.mBodies)});
    else
        AbortBatchParts(std::exchange(ioBatch.mState, nullptr), ioBatch.mBodies);
}

void BodyInterface::AbortDeferredBatches()
{
    if (!mBatches->HasDeferred() || !BodyManager::MayTakeBodyLocks()) return;
    const std::lock_guard drain(mBatches->DrainMutex());
    for (const AddBatchRegistry::Deferred& batch : mBatches->TakeDeferred())
        AbortBatchParts(batch.mState, batch.mBodies);
    mBatches->EndDrain();
}

BodyInterface::AddBatch::AddBatch(AddBatch&& ioOther) noexcept
{
    *this = std::move(ioOther); // Letting go of this empty batch does nothing
}

BodyInterface::AddBatch& BodyInterface::AddBatch::operator=(AddBatch&& ioOther) noexcept
{
    if (this == &ioOther) return *this;
    LetGo();
    mBodies = std::move(ioOther.mBodies);
    ioOther.mBodies.clear();
    mState = std::exchange(ioOther.mState, nullptr);
    mRegistry = std::move(ioOther.mRegistry);
    return *this;
}

BodyInterface::AddBatch::~AddBatch()
{
    LetGo();
}

void BodyInterface::AddBatch::LetGo() noexcept
{
    if (mState != nullptr && mRegistry != nullptr)
        // The registry keeps the world alive until LeaveDrop, or says that it is gone with the batch's state
        if (BodyInterface* world = mRegistry->EnterDrop(); world != nullptr)
        {
            world->AbortLetGo(*this);
            mRegistry->LeaveDrop();
        }
    mState = nullptr;
    mBodies.clear();
    mRegistry.reset();
}

template <class F> Status BodyInterface::ModifyBody(const BodyID& inID, bool inMustBeDynamic, F&& inChange)
{
    BodyLockWrite lock(mBodies, inID);
    if (lock.WasWrongThread()) return WrongThread();
    Body* body = lock.GetBody();
    if (body == nullptr) return StaleID();
    if (inMustBeDynamic && body->IsStatic())
        return MakeError(ErrorCode::InvalidArgument, "a static body has no velocity");
    return inChange(*body);
}

template <class T, class F> Result<T> BodyInterface::ReadBody(const BodyID& inID, F&& inRead) const
{
    BodyLockRead lock(mBodies, inID);
    if (lock.WasWrongThread()) return WrongThread();
    if (lock.GetBody() == nullptr) return StaleID();
    return inRead(*lock.GetBody());
}

void BodyInterface::OnBodyMoved(Body& ioBody, Activation inActivation)
{
    const AABB oldBounds = ioBody.mBounds;
    ioBody.UpdateBounds();
    if (!ioBody.mInWorld)
        mBodies.PublishPose(ioBody);
    else
    {
        // The broad phase holds both poses' bounds while the pose changes, so a query that reads either
        // pose finds the body (PublishedPose.h); then only the new one's
        AABB both = oldBounds;
        both.Encapsulate(ioBody.mBounds);
        const BroadPhaseBody during{ioBody.GetID(), both, ioBody.GetObjectLayer()};
        mBroadPhase.NotifyBodiesAABBChanged({&during, 1});
        mBodies.PublishPose(ioBody);
        const BroadPhaseBody entry = ToBroadPhase(ioBody);
        mBroadPhase.NotifyBodiesAABBChanged({&entry, 1});
        mBodies.NotifyChange(BodyChangeKind::Moved, ioBody, oldBounds);
        if (inActivation == Activation::Activate) mBodies.ActivateBody(ioBody);
    }
}

Status BodyInterface::SetPosition(const BodyID& inID, const Vec3& inPosition, Activation inActivation)
{
    if (!IsValidWorldPosition(inPosition)) return InvalidVector("position");
    return ModifyBody(inID, false,
                      [&](Body& ioBody)
                      {
                          ioBody.mPosition = inPosition + ioBody.mRotation * ioBody.mCenterOfMassOffset;
                          OnBodyMoved(ioBody, inActivation);
                          return Status::Ok();
                      });
}

Status BodyInterface::SetRotation(const BodyID& inID, const Quat& inRotation, Activation inActivation)
{
    if (!IsValidRotation(inRotation))
        return MakeError(ErrorCode::InvalidArgument, "rotation is not a finite unit quaternion");
    return ModifyBody(inID, false,
                      [&](Body& ioBody)
                      {
                          const Vec3 origin = ioBody.GetPosition();
                          ioBody.mRotation = inRotation.normalized();
                          ioBody.mPosition = origin + ioBody.mRotation * ioBody.mCenterOfMassOffset;
                          OnBodyMoved(ioBody, inActivation);
                          return Status::Ok();
                      });
}

Status BodyInterface::SetPositionAndRotation(const BodyID& inID, const Vec3& inPosition,
                                             const Quat& inRotation, Activation inActivation)
{
    if (!IsValidWorldPosition(inPosition)) return InvalidVector("position");
    if (!IsValidRotation(inRotation))
        return MakeError(ErrorCode::InvalidArgument, "rotation is not a finite unit quaternion");
    return ModifyBody(inID, false,
                      [&](Body& ioBody)
                      {
                          ioBody.mRotation = inRotation.normalized();
                          ioBody.mPosition = inPosition + ioBody.mRotation * ioBody.mCenterOfMassOffset;
                          OnBodyMoved(ioBody, inActivation);
                          return Status::Ok();
                      });
}

Status BodyInterface::SetLinearVelocity(const BodyID& inID, const Vec3& inVelocity)
{
    if (!IsFiniteLength(inVelocity)) return InvalidVector("linear velocity");
    return ModifyBody(inID, true,
                      [&](Body& ioBody)
                      {
                          ioBody.mLinearVelocity = inVelocity;
                          if (inVelocity.squaredNorm() > 0.0f) mBodies.ActivateBody(ioBody);
                          return Status::Ok();
                      });
}

Status BodyInterface::SetAngularVelocity(const BodyID& inID, const Vec3& inVelocity)
{
    if (!IsFiniteLength(inVelocity)) return InvalidVector("angular velocity");
    return ModifyBody(inID, true,
                      [&](Body& ioBody)
                      {
                          ioBody.mAngularVelocity = inVelocity;
                          if (inVelocity.squaredNorm() > 0.0f) mBodies.ActivateBody(ioBody);
                          return Status::Ok();
                      });
}

template <class F>
Status BodyInterface::PushBody(const BodyID& inID, const Vec3& inAmount, const char* inWhat, F&& inApply)
{
    if (!IsFiniteLength(inAmount)) return InvalidVector(inWhat);
    return ModifyBody(inID, true,
                      [&](Body& ioBody)
                      {
                          if (!ioBody.IsDynamic())
                              return Status(MakeError(ErrorCode::InvalidArgument,
                                                      std::string(inWhat) + " acts on dynamic bodies only"));
                          // Finite amounts can still add up to infinity (two forces of 2e38 N, or a huge
                          // impulse on a light body), which the step would turn into NaN: such a change is
                          // refused whole
                          const Vec3 force = ioBody.mForce, torque = ioBody.mTorque;
                          const Vec3 linear = ioBody.mLinearVelocity, angular = ioBody.mAngularVelocity;
                          inApply(ioBody);
                          if (!IsFiniteLength(ioBody.mForce) || !IsFiniteLength(ioBody.mTorque) ||
                              !IsFiniteLength(ioBody.mLinearVelocity) ||
                              !IsFiniteLength(ioBody.mAngularVelocity))
                          {
                              ioBody.mForce = force;
                              ioBody.mTorque = torque;
                              ioBody.mLinearVelocity = linear;
                              ioBody.mAngularVelocity = angular;
                              return Status(MakeError(ErrorCode::InvalidArgument,
                                                      std::string(inWhat) + " is too large: the body's " +
                                                          "accumulated force or velocity would overflow"));
                          }
                          mBodies.ActivateBody(ioBody);
                          return Status::Ok();
                      });
}

Status BodyInterface::AddForce(const BodyID& inID, const Vec3& inForce)
{
    return PushBody(inID, inForce, "force", [&](Body& ioBody) { ioBody.mForce += inForce; });
}

Status BodyInterface::AddTorque(const BodyID& inID, const Vec3& inTorque)
{
    return PushBody(inID, inTorque, "torque", [&](Body& ioBody) { ioBody.mTorque += inTorque; });
}

Status BodyInterface::AddImpulse(const BodyID& inID, const Vec3& inImpulse)
{
    return PushBody(inID, inImpulse, "impulse",
                    [&](Body& ioBody) { ioBody.mLinearVelocity += ioBody.mInvMass * inImpulse; });
}

Status BodyInterface::AddImpulse(const BodyID& inID, const Vec3& inImpulse, const Vec3& inWorldPoint)
{
    if (!IsValidWorldPosition(inWorldPoint)) return InvalidVector("impulse point");
    return PushBody(inID, inImpulse, "impulse",
                    [&](Body& ioBody)
                    {
                        ioBody.mLinearVelocity += ioBody.mInvMass * inImpulse;
                        ioBody.mAngularVelocity += ioBody.GetInverseInertiaWorld() *
                                                   (inWorldPoint - ioBody.mPosition).cross(inImpulse);
                    });
}

Status BodyInterface::AddAngularImpulse(const BodyID& inID, const Vec3& inImpulse)
{
    return PushBody(inID, inImpulse, "angular impulse",
                    [&](Body& ioBody)
                    { ioBody.mAngularVelocity += ioBody.GetInverseInertiaWorld() * inImpulse; });
}

Status BodyInterface::ActivateBody(const BodyID& inID)
{
    return ModifyBody(
        inID, false,
        [&](Body& ioBody)
        {
            if (!ioBody.mInWorld)
                return Status(MakeError(ErrorCode::NotAdded, "only bodies in the world can be activated"));
            mBodies.ActivateBody(ioBody);
            return Status::Ok();
        });
}

Status BodyInterface::DeactivateBody(const BodyID& inID)
{
    return ModifyBody(inID, false,
                      [&](Body& ioBody)
                      {
                          mBodies.DeactivateBody(ioBody);
                          return Status::Ok();
                      });
}

Status BodyInterface::SetMotionType(const BodyID& inID, MotionType inMotionType, Activation inActivation)
{
    if (!IsValidMotionType(inMotionType))
        return MakeError(ErrorCode::InvalidArgument, "motion type " + std::to_string(int(inMotionType)) +
                                                         " is not static, kinematic or dynamic");
    return ModifyBody(
        inID, false,
        [&](Body& ioBody)
        {
            // ActivateBody leaves static bodies and bodies outside the world alone
            auto activate = [&]
            {
                if (inActivation == Activation::Activate) mBodies.ActivateBody(ioBody);
            };
            if (ioBody.mMotionType == inMotionType)
            {
                activate();
                return Status::Ok();
            }
            if (inMotionType == MotionType::Dynamic)
                if (Status mass = Body::CheckDynamicMass(*ioBody.mShape, ioBody.mDensity); !mass)
                    return Status(MakeError(ErrorCode::InvalidArgument,
                                            "the body can not be made dynamic: " + mass.GetError().mMessage));
            const AABB bounds = ioBody.mBounds;
            // Under the old motion type: a listener that follows bodies of that type only lets it go
            if (ioBody.mInWorld) mBodies.NotifyChange(BodyChangeKind::Moved, ioBody, bounds);
            const Vec3 origin = ioBody.GetPosition();
            if (inMotionType == MotionType::Static)
            {
                // Out of the active list first (a static body never is in it): velocities and forces go too
                mBodies.DeactivateBody(ioBody);
                ioBody.mLinearVelocity.setZero();
                ioBody.mAngularVelocity.setZero();
            }
            if (inMotionType != MotionType::Dynamic)
            {
                // Forces move dynamic bodies only; a kinematic body would carry them to a later change
                ioBody.mForce.setZero();
                ioBody.mTorque.setZero();
            }
            ioBody.mMotionType = inMotionType;
            ioBody.SetMassProperties(true);
            ioBody.mPosition = origin + ioBody.mRotation * ioBody.mCenterOfMassOffset;
            ioBody.mSleepTimer = 0.0f;
            mBodies.PublishPose(ioBody); // The new motion type in the flags; the pose is the same
            if (ioBody.mInWorld)
            {
                // An active body's box is the swept one the step gave it: a static body's is its own bounds,
                // which hold its published pose's (it did not move)
                if (inMotionType == MotionType::Static)
                {
                    const BroadPhaseBody entry = ToBroadPhase(ioBody);
                    mBroadPhase.NotifyBodiesAABBChanged({&entry, 1});
                }
                mBodies.NotifyChange(BodyChangeKind::Moved, ioBody, bounds);
            }
            activate();
            return Status::Ok();
        });
}

Status BodyInterface::SetObjectLayer(const BodyID& inID, ObjectLayer inLayer)
{
    if (!mLayers.IsValid(inLayer))
        return MakeError(ErrorCode::InvalidArgument,
                         "object layer " + std::to_string(inLayer) + " is not in the layer setup");
    AbortDeferredBatches(); // A batch let go inside the step no longer holds the body's old layer
    return ModifyBody(
        inID, false,
        [&](Body& ioBody)
        {
            if (ioBody.mObjectLayer == inLayer) return Status::Ok();
            if (ioBody.mAddPending)
                return Status(MakeError(ErrorCode::InvalidArgument,
                                        "the body is in an add batch that is not finalized (which holds its "
                                        "layer): finalize or abort the batch first"));
            auto setLayer = [&]
            {
                ioBody.mObjectLayer = inLayer;
                mBodies.PublishPose(ioBody);
            };
            if (!ioBody.mInWorld)
            {
                setLayer();
                return Status::Ok();
            }
            const AABB bounds = ioBody.mBounds;
            mBodies.NotifyChange(BodyChangeKind::Moved, ioBody, bounds); // Under the old layer, as above
            // The broad phase runs setLayer while the body is found under both layers: the published layer
            // changes while a query of either finds it
            if (!mBroadPhase.ChangeBodyLayer(ioBody.GetID(), inLayer, setLayer))
                return Status(
                    MakeError(ErrorCode::OutOfCapacity, "the broad phase has no room to move the body to "
                                                        "object layer " +
                                                            std::to_string(inLayer) + cBroadPhaseFullHint));
            mBodies.NotifyChange(BodyChangeKind::Moved, ioBody, bounds);
            return Status::Ok();
        });
}

Status BodyInterface::SetShape(const BodyID& inID, ShapeRef inShape, bool inUpdateMassProperties,
                               Activation inActivation)
{
    if (inShape == nullptr) return MakeError(ErrorCode::InvalidArgument, "the new shape is null");
    ShapeRef old; // Retired once the body's lock is released
    const Status status = ModifyBody(
        inID, false,
        [&](Body& ioBody)
        {
            // CreateBody's checks of the shape, at the body's pose
            const AABB bounds = inShape->GetWorldBounds(ioBody.GetTransform());
            if (!bounds.IsFinite())
                return Status(MakeError(ErrorCode::InvalidArgument,
                                        "the new shape's bounds at the body's pose are not finite"));
            if (bounds.IsEmpty())
                return Status(MakeError(ErrorCode::InvalidArgument,
                                        "the new shape's bounds are empty: the shape has no extent"));
            if (ioBody.IsDynamic())
                if (Status mass = Body::CheckDynamicMass(*inShape, ioBody.mDensity); !mass) return mass;
            const Vec3 origin = ioBody.GetPosition();
            const Vec3 oldCenterOfMass = ioBody.mPosition;
            old = std::move(ioBody.mShape);
            ioBody.mShape = std::move(inShape);
            ++ioBody.mShapeGeneration; // The step's pair cache must collide the new shape, not reuse the old
            ioBody.SetMassProperties(inUpdateMassProperties);
            ioBody.mPosition = origin + ioBody.mRotation * ioBody.mCenterOfMassOffset;
            // The same rigid motion, now about the new centre of mass: v(p) = v + w x (p - c) at the new c
            if (!ioBody.IsStatic())
                ioBody.mLinearVelocity += ioBody.mAngularVelocity.cross(ioBody.mPosition - oldCenterOfMass);
            // Grows the broad phase over both shapes' bounds, publishes the new shape, shrinks to its bounds
            OnBodyMoved(ioBody, inActivation);
            return Status::Ok();
        });
    // The published pose names the new shape now; a query may still hold the old one (as after DestroyBody)
    mBodies.RetireShape(std::move(old));
    return status;
}

Status BodyInterface::MoveKinematic(const BodyID& inID, const Vec3& inTargetPosition,
                                    const Quat& inTargetRotation, float inDeltaTime)
{
    if (!IsValidWorldPosition(inTargetPosition)) return InvalidVector("target position");
    if (!IsValidRotation(inTargetRotation))
        return MakeError(ErrorCode::InvalidArgument, "target rotation is not a finite unit quaternion");
    if (!std::isfinite(inDeltaTime) || !(inDeltaTime > 0.0f))
        return MakeError(ErrorCode::InvalidArgument, "delta time must be finite and > 0");
    return ModifyBody(
        inID, false,
        [&](Body& ioBody)
        {
            if (!ioBody.IsKinematic())
                return Status(MakeError(ErrorCode::InvalidArgument,
                                        std::string("MoveKinematic moves kinematic bodies; this one is ") +
                                            MotionTypeName(ioBody.mMotionType)));
            if (!ioBody.mInWorld)
                return Status(
                    MakeError(ErrorCode::NotAdded, "only a body in the world moves by its velocity"));
            const Quat target = inTargetRotation.normalized();
            // The centre of mass moves in a straight line (the step moves it by its velocity)
            const Vec3 linear =
                (inTargetPosition + target * ioBody.mCenterOfMassOffset - ioBody.mPosition) / inDeltaTime;
            // The turn from the rotation now to the target, the short way round; the step turns a body by
            // exp(w dt), so w is the turn's rotation vector over the time
            Quat turn = target * ioBody.mRotation.conjugate();
            if (turn.w() < 0.0f) turn.coeffs() = -turn.coeffs();
            const float sinHalf = turn.vec().norm();
            const float angle = 2.0f * std::atan2(sinHalf, turn.w());
            // Near zero, angle / sin(angle / 2) tends to 2
            const Vec3 rotation =
                sinHalf > 1.0e-6f ? Vec3(turn.vec() * (angle / sinHalf)) : Vec3(2.0f * turn.vec());
            const Vec3 angular = rotation / inDeltaTime;
            if (!IsFiniteLength(linear) || !IsFiniteLength(angular))
                return Status(
                    MakeError(ErrorCode::InvalidArgument,
                              "the move needs a velocity too large to represent (delta time too small)"));
            // The step clamps a kinematic body's velocities to its limits: it would stop short of the target
            if (linear.norm() > ioBody.mMaxLinearVelocity)
                return Status(MakeError(ErrorCode::InvalidArgument,
                                        "the move needs " + std::to_string(linear.norm()) +
                                            " m/s, over the body's limit of " +
                                            std::to_string(ioBody.mMaxLinearVelocity) + " m/s"));
            if (angular.norm() > ioBody.mMaxAngularVelocity)
                return Status(MakeError(ErrorCode::InvalidArgument,
                                        "the move needs " + std::to_string(angular.norm()) +
                                            " rad/s, over the body's limit of " +
                                            std::to_string(ioBody.mMaxAngularVelocity) + " rad/s"));
            ioBody.mLinearVelocity = linear;
            ioBody.mAngularVelocity = angular;
            if (linear.squaredNorm() > 0.0f || angular.squaredNorm() > 0.0f) mBodies.ActivateBody(ioBody);
            return Status::Ok();
        });
}

Result<Vec3> BodyInterface::GetPosition(const BodyID& inID) const
{
    return ReadBody<Vec3>(inID, [](const Body& inBody) { return inBody.GetPosition(); });
}
Result<Quat> BodyInterface::GetRotation(const BodyID& inID) const
{
    return ReadBody<Quat>(inID, [](const Body& inBody) { return inBody.GetRotation(); });
}
Result<Vec3> BodyInterface::GetLinearVelocity(const BodyID& inID) const
{
    return ReadBody<Vec3>(inID, [](const Body& inBody) { return inBody.GetLinearVelocity(); });
}
Result<Vec3> BodyInterface::GetAngularVelocity(const BodyID& inID) const
{
    return ReadBody<Vec3>(inID, [](const Body& inBody) { return inBody.GetAngularVelocity(); });
}
Result<AABB> BodyInterface::GetWorldBounds(const BodyID& inID) const
{
    return ReadBody<AABB>(inID, [](const Body& inBody) { return inBody.GetWorldBounds(); });
}
Result<bool> BodyInterface::IsActive(const BodyID& inID) const
{
    return ReadBody<bool>(inID, [](const Body& inBody) { return inBody.IsActive(); });
}
Result<bool> BodyInterface::IsAdded(const BodyID& inID) const
{
    return ReadBody<bool>(inID, [](const Body& inBody) { return inBody.IsInWorld(); });
}

} // namespace cairn::physics
