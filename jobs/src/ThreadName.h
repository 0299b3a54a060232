#pragma once

// Names a scheduler's threads, so that profilers, debuggers and tools that watch threads (the demo's count of
// times another task took a frame thread's core) can tell them apart.

#include <cstdint>
#include <cstdio>
#include <pthread.h>
#include <thread>

namespace cairn::jobs
{

/// Names inThread inPrefix-inIndex (Linux keeps 15 characters). A hint: a name that cannot be set is left.
inline void NameThread(std::thread& inThread, const char* inPrefix, uint32_t inIndex)
{
#if defined(__linux__)
    char name[16];
    std::snprintf(name, sizeof(name), "%s-%u", inPrefix, unsigned(inIndex));
    (void)pthread_setname_np(inThread.native_handle(), name);
#else
    (void)inThread;
    (void)inPrefix;
    (void)inIndex;
#endif
}

} // namespace cairn::jobs
