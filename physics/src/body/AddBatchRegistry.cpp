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
    return std::exchange(mDeferred, {});
}

void AddBatchRegistry::EndDrain()
{
    const std::lock_guard lock(mMutex);
    // Relaxed: a hint, see HasDeferred. Cleared only now, so that a call starting during the aborts saw it
    // set and waited for them on the drain mutex
    if (mDeferred.empty()) mHasDeferred.store(false, std::memory_order_relaxed);
}

std::vector<BroadPhase::AddState> AddBatchRegistry::Close()
{
    std::unique_lock lock(mMutex);
    mOwner = nullptr; // Before the wait: drops that keep coming cannot hold it off
    mNoDropsInFlight.wait(lock, [&] { return mDropsInFlight == 0; });
    mDeferred.clear();
    std::vector<BroadPhase::AddState> live(mLive.begin(), mLive.end());
    mLive.clear();
    return live;
}

} // namespace cairn::physics
