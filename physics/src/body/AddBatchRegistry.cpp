#include "body/AddBatchRegistry.h"

#include <utility>

namespace cairn::physics
{

void AddBatchRegistry::Register(BroadPhase::AddState inState)
{
    const std::lock_guard lock(mMutex);
    mLive.insert(inState);
}

void AddBatchRegistry::Unregister(BroadPhase::AddState inState)
{
    const std::lock_guard lock(mMutex);
    mLive.erase(inState);
}

BodyInterface* AddBatchRegistry::EnterDrop()
{
    const std::lock_guard lock(mMutex);
    if (mOwner != nullptr) ++mDropsInFlight;
    return mOwner;
}

void AddBatchRegistry::LeaveDrop()
{
    const std::lock_guard lock(mMutex);
    if (--mDropsInFlight == 0) mNoDropsInFlight.notify_all();
}

void AddBatchRegistry::Defer(Deferred&& inBatch)
{
    const std::lock_guard lock(mMutex);
    mDeferred.push_back(std::move(inBatch));
    mHasDeferred.store(true, std::memory_order_relaxed); // Relaxed: read as a hint, see HasDeferred
}

std::vector<AddBatchRegistry::Deferred> AddBatchRegistry::TakeDeferred()
{
    const std::lock_guard lock(mMutex);
    mHasDeferred.store(false, std::memory_order_relaxed); // Relaxed: a hint, see HasDeferred
    return std::exchange(mDeferred, {});
}

std::vector<BroadPhase::AddState> AddBatchRegistry::Close()
{
    std::unique_lock lock(mMutex);
    mNoDropsInFlight.wait(lock, [&] { return mDropsInFlight == 0; });
    mOwner = nullptr;
    mDeferred.clear();
    std::vector<BroadPhase::AddState> live(mLive.begin(), mLive.end());
    mLive.clear();
    return live;
}

} // namespace cairn::physics
