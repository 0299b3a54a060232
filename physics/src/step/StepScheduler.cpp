#include "StepScheduler.h"

#include "math/CpuPause.h"

#include <thread>

namespace cairn::physics
{

void StepScheduler::ResetParts(uint32_t inParts)
{
    for (uint32_t part = 0; part < inParts; ++part)
    {
        // Relaxed: the loop of the threads starts after this, and handing out its parts orders these stores
        // before them
        mParts[part].mClaimed.store(0, std::memory_order_relaxed);
        mParts[part].mDone.store(0, std::memory_order_relaxed);
    }
    mStagesOver.store(false, std::memory_order_relaxed); // Relaxed: as above
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
