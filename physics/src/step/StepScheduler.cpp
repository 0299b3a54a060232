#include "StepScheduler.h"

#include "math/CpuPause.h"

#include <thread>

namespace cairn::physics
{

void StepScheduler::ResetParts(uint32_t inParts)
{
    for (uint32_t part = 0; part < inParts; ++part)
    {
        // Relaxed: the helper tasks are started after this, and starting one orders these stores before it
        mParts[part].mClaimed.store(0, std::memory_order_relaxed);
        mParts[part].mDone.store(0, std::memory_order_relaxed);
    }
}

void StepScheduler::WaitABit(uint32_t inSpins)
{
    if (inSpins < 256)
    {
        CpuPause();
    }
    else
        std::this_thread::yield();
}

} // namespace cairn::physics
