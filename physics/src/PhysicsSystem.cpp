#include "cairn/physics/PhysicsSystem.h"

#include "PhysicsStep.h"
#include "broadphase/BroadPhaseBruteForce.h"
#include "broadphase/BroadPhaseGlobalMutex.h"
#include "broadphase/BroadPhaseQuadTree.h"
#include "cairn/physics/LockWaits.h"

#include <string>
#include <utility>

namespace cairn::physics
{

namespace
{
std::unique_ptr<BroadPhase> CreateBroadPhase(const PhysicsSettings& inSettings, const LayerSetup& inLayers)
{
    auto quadTree = [&]
    {
        auto broadPhase = std::make_unique<BroadPhaseQuadTree>(inSettings.mMaxBodies, inLayers);
        broadPhase->SetCandidateCacheMargin(inSettings.mBroadPhaseCandidateMargin);
        return broadPhase;
    };
    switch (inSettings.mBroadPhase)
    {
    case BroadPhaseType::BruteForce:
        return std::make_unique<BroadPhaseBruteForce>();
    case BroadPhaseType::QuadTree:
        return quadTree();
    case BroadPhaseType::QuadTreeGlobalMutex:
        return std::make_unique<BroadPhaseGlobalMutex>(quadTree());
    }
    return nullptr;
}

/// WrongThread for a call that would take every body lock (inCall: Update, OptimizeBroadPhase) from inside
/// the step or while this thread holds a body lock, where it would deadlock; else Ok.
Status CheckMayLockAllBodies(const char* inCall)
{
    if (BodyManager::IsInsideStep())
        return MakeError(ErrorCode::WrongThread,
                         std::string(inCall) + " called from inside the physics step");
    if (BodyManager::GetBodyLocksHeldByThisThread() > 0)
        return MakeError(ErrorCode::WrongThread, std::string(inCall) +
                                                     " called while this thread holds a body lock (it would "
                                                     "deadlock)");
    return Status::Ok();
}

/// Runs a function when it goes out of scope, whichever way: a return or an exception.
template <class Function> class ScopeExit
{
public:
    explicit ScopeExit(Function inFunction) : mFunction(std::move(inFunction)) {}
    ~ScopeExit() { mFunction(); }
    ScopeExit(const ScopeExit&) = delete;
    ScopeExit& operator=(const ScopeExit&) = delete;

private:
    Function mFunction;
};

Status ValidateSetup(const PhysicsSettings& inSettings, const LayerSetup& inLayers)
{
    if (Status settings = ValidateSettings(inSettings); !settings) return settings;
    return inLayers.GetStatus();
}
} // namespace

Result<std::unique_ptr<PhysicsSystem>> PhysicsSystem::Create(const PhysicsSettings& inSettings,
                                                             const LayerSetup& inLayers)
{
    if (Status setup = ValidateSetup(inSettings, inLayers); !setup) return setup.GetError();
    // new rather than std::make_unique: the constructor is private
    return std::unique_ptr<PhysicsSystem>(new PhysicsSystem(inSettings, inLayers));
}

PhysicsSystem::PhysicsSystem(const PhysicsSettings& inSettings, const LayerSetup& inLayers)
    : mSettings(inSettings), mLayers(inLayers),
      mBodies(std::make_unique<BodyManager>(mSettings.mMaxBodies, mSettings.mNumBodyMutexes)),
      mBroadPhase(CreateBroadPhase(mSettings, mLayers)),
      mBodyInterface(std::make_unique<BodyInterface>(*mBodies, *mBroadPhase, mLayers)),
      mConstraints(std::make_unique<ConstraintManager>()),
      mConstraintInterface(std::make_unique<ConstraintInterface>(*mConstraints, *mBodies)),
      mWorldQuery(std::make_unique<WorldQuery>(*mBodies, *mBroadPhase, mSettings.mQueryReads)),
      mStep(std::make_unique<PhysicsStep>(mSettings, mLayers, *mBodies, *mBroadPhase, *mConstraints))
{
}

PhysicsSystem::~PhysicsSystem() = default;

bool PhysicsSystem::IsContactCacheConsistent() const
{
    return mStep->IsContactCacheConsistent();
}

Status PhysicsSystem::Update(float inDeltaTime, int inCollisionSteps)
{
    return UpdateImpl(inDeltaTime, inCollisionSteps, nullptr);
}

Status PhysicsSystem::Update(float inDeltaTime, int inCollisionSteps, jobs::JobInterface& ioJobs)
{
    return UpdateImpl(inDeltaTime, inCollisionSteps, &ioJobs);
}

Status PhysicsSystem::OptimizeBroadPhase()
{
    if (Status may = CheckMayLockAllBodies("OptimizeBroadPhase"); !may) return may;
    // Acquire and release as Update's: the broad phase's update state passes between the two
    if (mUpdating.exchange(true, std::memory_order_acquire))
        return MakeError(ErrorCode::WrongThread,
                         "OptimizeBroadPhase called while Update runs on another thread");
    bool locked = false;
    const ScopeExit release(
        [&]
        {
            if (locked) mBodies->UnlockAllBodies();
            mUpdating.store(false, std::memory_order_release);
        });
    mBodies->LockAllBodies();
    locked = true;
    // A rebuild retires the nodes it replaces, and the next update frees them once no query can still be
    // walking them: the second frees what the first retired (and what removed bodies held)
    mBroadPhase->Update();
    mBroadPhase->Update();
    return Status::Ok();
}

Status PhysicsSystem::UpdateImpl(float inDeltaTime, int inCollisionSteps, jobs::JobInterface* ioJobs)
{
    if (!std::isfinite(inDeltaTime) || inDeltaTime <= 0.0f || inDeltaTime > 1.0f)
        return MakeError(ErrorCode::InvalidArgument, "time step must be in (0, 1] s");
    if (inCollisionSteps < 1 || inCollisionSteps > 16)
        return MakeError(ErrorCode::InvalidArgument, "collision steps must be in 1..16");
    if (Status may = CheckMayLockAllBodies("Update"); !may) return may;
    // Acquire pairs with the release below, so a step sees everything the previous updating thread wrote
    if (mUpdating.exchange(true, std::memory_order_acquire))
        return MakeError(ErrorCode::WrongThread, "Update is already running on another thread");

    // From here on, every way out (an exception from inside the step too: a BodyChangeListener that throws,
    // std::bad_alloc) frees the body locks and this thread's inside-step mark with them, collects the shapes
    // of bodies destroyed meanwhile, and clears the updater flag last, so that no other Update starts before
    // the rest is undone
    bool locked = false;
    const ScopeExit release(
        [&]
        {
            if (locked) mBodies->UnlockAllBodies();
            // Shapes of bodies destroyed meanwhile, once no query can hold them
            mBodies->CollectRetiredShapes();
            // Release: the next updater sees everything this one wrote (pairs with the acquire above)
            mUpdating.store(false, std::memory_order_release);
        });
    if (mStepInterrupted)
    {
        // The step's state between steps is caches only (bodies, their poses and the broad phase live
        // elsewhere), so a fresh one is a world's first step again, with nothing to warm-start from
        mStep = std::make_unique<PhysicsStep>(mSettings, mLayers, *mBodies, *mBroadPhase, *mConstraints);
        mStepInterrupted = false;
    }

    const uint64_t waitedBefore = GetThisThreadLockWaitNanoseconds();
    mBodies->LockAllBodies();
    locked = true;
    // The joints' mutex after the body mutexes (ConstraintManager.h): released before them, at scope exit
    const std::lock_guard jointsLock(mConstraints->GetMutex());
    mLastStatistics = {};
    mLastStatistics.mLockWaitMs = double(GetThisThreadLockWaitNanoseconds() - waitedBefore) / 1.0e6;
    const float stepTime = inDeltaTime / float(inCollisionSteps);
    const bool recordEvents = mRecordContactEvents || mContactListener != nullptr;
    mContactEvents.clear();
    try
    {
        for (int step = 0; step < inCollisionSteps; ++step)
        {
            const CollisionStepInfo info{uint8_t(step), step + 1 == inCollisionSteps, mContactListener,
                                         recordEvents ? &mContactEvents : nullptr};
            mStep->Run(stepTime, info, mLastStatistics, ioJobs);
        }
    }
    catch (...)
    {
        // Stopped halfway, its caches (contact cache, pair and island reuse) possibly half updated: the next
        // Update starts from a fresh step. The bodies are left as the step last wrote them, each whole: what
        // can throw (a listener, told after a change; an allocation) comes between changes to a body
        mStepInterrupted = true;
        throw;
    }
    return Status::Ok();
}

} // namespace cairn::physics
