#pragma once

// AddBatchRegistry: what a world knows of its add batches that are neither finalized nor aborted, so that a
// batch the game lets go is aborted instead of leaking its broad-phase state and leaving its bodies pending
// for good, whenever and wherever it is let go:
// - on a thread that may lock bodies: at once, by the owning BodyInterface;
// - inside a step, or on a thread that holds a body lock (where an abort could deadlock on its bodies'
//   locks): deferred, and aborted by the next BodyInterface call that can take those bodies or wait on them;
// - after its world is gone: nothing to do, the world aborted every batch it still had when it went.
//
// Threads: any thread that prepares, finalizes, aborts or lets go of a batch, and the thread that destroys
// the world. Every member but mDrainMutex is under mMutex, a leaf lock: nothing else is locked while it is
// held, so a thread may take it whatever body locks it holds. mDrainMutex is held across the aborts of
// deferred batches, which lock bodies: only a thread that holds no body lock takes it (lock order:
// mDrainMutex, body mutexes, the broad phase). Shared (std::shared_ptr) between the world and its batches,
// which may outlive it.

#include "cairn/physics/broadphase/BroadPhase.h"

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <unordered_set>
#include <vector>

namespace cairn::physics
{

class BodyInterface;

class AddBatchRegistry
{
public:
    /// A batch let go where it could not be aborted: its broad-phase state and the bodies it holds pending
    struct Deferred
    {
        BroadPhase::AddState mState = nullptr;
        std::vector<BroadPhaseBody> mBodies;
    };

    explicit AddBatchRegistry(BodyInterface& inOwner) : mOwner(&inOwner) {}

    void Register(BroadPhase::AddState inState);
    void Unregister(BroadPhase::AddState inState);

    /// A batch being let go: the world to abort it with, which stays alive until LeaveDrop, or nullptr when
    /// the world is gone or going (Close then aborts the batch's state)
    BodyInterface* EnterDrop();
    void LeaveDrop();

    /// Keeps a batch let go where it could not be aborted, for TakeDeferred (its state stays registered)
    void Defer(Deferred&& inBatch);
    bool HasDeferred() const
    {
        // Relaxed: a hint that saves the locks. A deferral that happened before this call (the step that let
        // the batch go has returned) is seen by coherence; one running now may be missed like one just after
        return mHasDeferred.load(std::memory_order_relaxed);
    }
    /// Held by the thread that aborts the deferred batches, from TakeDeferred to EndDrain: a call that starts
    /// meanwhile waits for those aborts instead of finding their bodies still pending
    std::mutex& DrainMutex() { return mDrainMutex; }
    /// The deferred batches, handed over once: the caller aborts them (unregistering their states), then
    /// calls EndDrain
    std::vector<Deferred> TakeDeferred();
    /// After the aborts of TakeDeferred's batches: HasDeferred turns false unless more were deferred since
    void EndDrain();

    /// The world is going: turns new drops away, waits for those in flight, then returns every state still
    /// registered (the caller aborts them while its broad phase lives). Later drops do nothing.
    std::vector<BroadPhase::AddState> Close();

private:
    std::mutex mDrainMutex;
    std::mutex mMutex;
    std::condition_variable mNoDropsInFlight;
    BodyInterface* mOwner;       ///< nullptr once Close began: no drop uses the world after that
    uint32_t mDropsInFlight = 0; ///< Between EnterDrop and LeaveDrop: Close waits for them
    std::unordered_set<BroadPhase::AddState> mLive;
    std::vector<Deferred> mDeferred;
    std::atomic<bool> mHasDeferred{false};
};

} // namespace cairn::physics
