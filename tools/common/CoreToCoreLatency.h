#pragma once

// CoreToCoreLatency: how long a cache line written on one core takes to be read on another and the answer to
// come back, measured with two threads passing a counter between them. A figure to read thread scaling
// against: every line that one thread writes and another reads next (a body integrated on one core and
// collided on the other) crosses at this cost. On a host whose cores share an L3 it is some tens of
// nanoseconds; two virtual CPUs on different dies of a server CPU take several times that, and a
// memory-bound loop then gains little from a second thread. The threads are not pinned (the OS places them;
// with two spinning at once they are on two cores). Main thread; takes a few milliseconds.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

namespace cairn::tools
{

/// Spins until ioCounter holds inValue; yields after a long wait, so that two threads sharing one core (an
/// oversubscribed host) still get through, slowly.
inline void WaitFor(const std::atomic<uint32_t>& inCounter, uint32_t inValue)
{
    // Acquire: pairs with the other side's release of inValue
    for (uint32_t spins = 0; inCounter.load(std::memory_order_acquire) != inValue; ++spins)
        if (spins >= (1u << 16)) std::this_thread::yield();
}

/// The median over batches of the round trip, in ns; 0 when the machine has one hardware thread.
inline double MeasureCoreToCoreRoundTripNanoseconds()
{
    if (std::thread::hardware_concurrency() < 2) return 0.0;
    constexpr uint32_t cBatches = 15, cRoundTrips = 2000;
    // Odd values are the main thread's passes, even ones the partner's answers
    alignas(64) std::atomic<uint32_t> counter{0};
    std::thread partner(
        [&counter]
        {
            for (uint32_t pass = 1; pass < 2 * cBatches * cRoundTrips; pass += 2)
            {
                // Acquire/release: each side's next pass follows the other's, nothing else is shared
                WaitFor(counter, pass);
                counter.store(pass + 1, std::memory_order_release);
            }
        });
    std::vector<double> batches;
    uint32_t value = 0;
    for (uint32_t batch = 0; batch < cBatches; ++batch)
    {
        const auto start = std::chrono::steady_clock::now();
        for (uint32_t trip = 0; trip < cRoundTrips; ++trip)
        {
            counter.store(++value, std::memory_order_release); // Release/acquire: as the partner's
            ++value;
            WaitFor(counter, value);
        }
        batches.push_back(
            std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count() /
            cRoundTrips);
    }
    partner.join();
    std::nth_element(batches.begin(), batches.begin() + cBatches / 2, batches.end());
    return batches[cBatches / 2];
}

} // namespace cairn::tools
