#include "StepScheduler.h"

#include "math/CpuPause.h"

#include <thread>

namespace cairn::physics
{

void StepScheduler::ResetStages(uint32_t inNumStages)
{
    if (mStageCapacity < inNumStages)
    {
        mStages = std::make_unique<StageCounters[]>(inNumStages);
        mStageCapacity = inNumStages;
    }
    for (uint32_t stage = 0; stage < inNumStages; ++stage)
    {
        // Relaxed: the helper tasks are started after this, and starting one orders these stores before it
        mStages[stage].mClaimed.store(0, std::memory_order_relaxed);
        mStages[stage].mDone.store(0, std::memory_order_relaxed);
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
