#include "PairCandidateCache.h"

#include <algorithm>
#include <bit>

namespace cairn::physics
{

void PairCandidateCache::Prepare(uint32_t inNumActive)
{
    const uint64_t wanted = std::max<uint64_t>(64, 2 * uint64_t(inNumActive));
    if (mCapacity < wanted)
    {
        mCapacity = uint32_t(std::bit_ceil(std::min<uint64_t>(wanted, 1u << 31)));
        mHashShift = 32 - uint32_t(std::countr_zero(mCapacity));
        mEntries = std::make_unique<Entry[]>(mCapacity);
        mBytes.store(size_t(mCapacity) * sizeof(Entry), std::memory_order_relaxed); // A statistic
        mUsed.store(0, std::memory_order_relaxed);                                  // No range runs yet
        return;
    }
    // Relaxed: the ranges of the last call have finished (their ParallelFor returned)
    if (mUsed.load(std::memory_order_relaxed) <= mCapacity / 2) return;
    for (uint32_t i = 0; i < mCapacity; ++i)
        mEntries[i].mKey.store(cEmptyKey, std::memory_order_relaxed); // As above
    mUsed.store(0, std::memory_order_relaxed);
}

PairCandidateCache::Entry* PairCandidateCache::FindOrClaim(uint32_t inIndex)
{
    if (mCapacity == 0 || inIndex == cEmptyKey) return nullptr;
    const uint32_t mask = mCapacity - 1;
    uint32_t slot = HomeSlot(inIndex);
    for (uint32_t probe = 0; probe < mCapacity; ++probe, slot = (slot + 1) & mask)
    {
        Entry& entry = mEntries[slot];
        // Relaxed (here and below): a key only tells a thread which entry is its own; an entry's payload is
        // read and written only by the thread that owns its body in this call (see the header)
        uint32_t key = entry.mKey.load(std::memory_order_relaxed);
        if (key == inIndex) return &entry;
        if (key != cEmptyKey) continue;
        if (mUsed.load(std::memory_order_relaxed) >= mCapacity - mCapacity / 4) return nullptr;
        if (entry.mKey.compare_exchange_strong(key, inIndex, std::memory_order_relaxed))
        {
            mUsed.fetch_add(1, std::memory_order_relaxed);
            entry.mGeneration = 0; // Whatever a cleared entry held is not valid
            return &entry;
        }
        // Another body took this slot first: probe on (it is not ours, only one thread claims an index)
    }
    return nullptr;
}

} // namespace cairn::physics
