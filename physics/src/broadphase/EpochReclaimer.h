#pragma once

// EpochReclaimer: tells the quad tree when nothing a query might still be reading can be freed. Queries
// never wait for it and it never waits for queries (epoch-based reclamation with striped reader counts).
//
// How: a global epoch counter E. A reader entering a read section adds itself to the count of its stripe for
// the parity of E, then checks that E did not change meanwhile (if it did, it leaves and retries: it is never
// blocked, at worst it re-reads E). The updater retires nodes (after unlinking them) tagged with the current
// epoch and, at each CollectGarbage, advances E by one only when no reader of the previous epoch's parity is
// left. A reader inside a section entered at epoch e <= r, so memory retired at epoch r is unreachable once E
// has advanced twice past r (E >= r + 2): the advance to r + 1 waited out the readers of r - 1, the one to
// r + 2 those of r. The retired lists are tagged by epoch, so any number of tree swaps per update is safe.
//
// Threads: Enter/Exit (through ReadScope, or PoseReader) from any thread, any number at once. TryAdvance from
// one thread at a time: the callers serialise it (the quad trees' body table under a mutex, since rebuilds
// and layer changes both advance its epoch; the published poses under their retired-list mutex). GetEpoch
// from any thread. Stripes keep readers on different threads off each other's cache lines: the reference
// engine's single read-write mutex cost each thread 500 us per frame in contention, 32 stripes 10 us. Memory
// orders: the reader's increment and re-check and the updater's count check and advance are seq_cst, because
// the argument above needs one total order of "reader registered" and "epoch advanced" (a store-load pattern
// that acquire/release does not order).

#include <atomic>
#include <cstdint>

namespace cairn::physics
{

class EpochReclaimer
{
public:
    static constexpr uint32_t cNumStripes = 32;

    /// A read section: nothing retired after it began is freed before it ends. Not movable.
    class ReadScope
    {
    public:
        explicit ReadScope(const EpochReclaimer& inReclaimer) : mCounter(inReclaimer.Enter(&mEpoch)) {}
        ~ReadScope() { Exit(mCounter); }
        ReadScope(const ReadScope&) = delete;
        ReadScope& operator=(const ReadScope&) = delete;
        /// The epoch the section was entered at: while the section lasts, the epoch is at most one past it.
        uint64_t GetEpoch() const { return mEpoch; }

    private:
        uint64_t mEpoch = 0; ///< Set by Enter, before mCounter (declared first: initialised first)
        std::atomic<uint32_t>& mCounter;
    };

    /// Enters a read section and returns the counter that Exit must be given to leave it; outEpoch (if not
    /// null) gets the epoch it was entered at. ReadScope pairs them; PoseReader calls them itself, because
    /// its installed header must not name this internal class.
    std::atomic<uint32_t>& Enter(uint64_t* outEpoch = nullptr) const;
    /// Leaves the read section that Enter returned ioCounter for.
    static void Exit(std::atomic<uint32_t>& ioCounter)
    {
        // Release: our reads of retired memory happen before the updater sees the count drop
        ioCounter.fetch_sub(1, std::memory_order_release);
    }

    EpochReclaimer() = default;
    EpochReclaimer(const EpochReclaimer&) = delete;
    EpochReclaimer& operator=(const EpochReclaimer&) = delete;

    /// Current epoch. Any thread.
    uint64_t GetEpoch() const
    {
        return mEpoch.load(std::memory_order_seq_cst); // Part of the total order, see the header comment
    }

    /// Advances the epoch when no reader of the previous one is left; never waits. One caller at a time.
    bool TryAdvance();

    /// True when memory retired at inRetiredEpoch can no longer be reached by any reader.
    bool IsSafeToFree(uint64_t inRetiredEpoch) const { return GetEpoch() >= inRetiredEpoch + 2; }

private:
    struct alignas(64) Stripe
    {
        mutable std::atomic<uint32_t> mReaders[2] = {0, 0}; ///< Readers inside, by the parity of their epoch
    };

    Stripe mStripes[cNumStripes];
    std::atomic<uint64_t> mEpoch = 2; ///< Starts at 2 so that "retired + 2" never wraps below zero
};

} // namespace cairn::physics
