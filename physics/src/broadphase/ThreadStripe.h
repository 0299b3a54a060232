#pragma once

// ThreadStripe: a small per-thread number used to spread threads over striped counters and locks. Threads
// get consecutive numbers in the order they first ask, so up to N threads land on N different stripes (a hash
// of the thread id can put two busy threads on one stripe).

#include <atomic>
#include <cstdint>

namespace cairn::physics
{

/// This thread's stripe in [0, inNumStripes); inNumStripes must be a power of two.
inline uint32_t GetThreadStripe(uint32_t inNumStripes)
{
    static std::atomic<uint32_t> sNextThread = 0;
    // Relaxed: only distinctness of the values matters
    thread_local const uint32_t tThread = sNextThread.fetch_add(1, std::memory_order_relaxed);
    return tThread & (inNumStripes - 1);
}

} // namespace cairn::physics
