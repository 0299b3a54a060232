#pragma once

// BenchSpin: arithmetic that the compiler cannot drop, one dependent chain, so that a benchmark's work takes
// a fixed time per iteration (about 1 ns) whatever the thread count: the job system's and the stages' loads.
// Any thread.

#include <cmath>
#include <cstdint>

namespace cairn::tools
{

inline float Spin(uint32_t inIterations, float inSeed)
{
    float x = inSeed;
    for (uint32_t i = 0; i < inIterations; ++i)
        x = x * 0.999f + std::sqrt(x + float(i & 7));
    return x;
}

} // namespace cairn::tools
