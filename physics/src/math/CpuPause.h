#pragma once

#if defined(__x86_64__) || defined(_M_X64)
#include <immintrin.h>
#endif

namespace cairn::physics
{

/// A spin-wait hint to the core: the loop backs off a little and leaves its hyper-thread sibling the
/// pipeline.
inline void CpuPause()
{
#if defined(__x86_64__) || defined(_M_X64)
    _mm_pause();
#endif
}

} // namespace cairn::physics
