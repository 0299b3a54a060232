#pragma once

// PinnedThread: pins the thread that makes it to the first core the process may run on, and gives it back
// its old cores when it goes. A game's main thread beside a JobSystem with mPinWorkers (whose workers take
// the other cores): with idle time between frames, the OS woke the main thread on a worker's core and took
// milliseconds to move it, so the frame's short parallel loops ran on one core.
// Threads: made and destroyed on the thread it pins.

#include <pthread.h>
#include <sched.h>

namespace cairn::tools
{

class PinnedThread
{
public:
    explicit PinnedThread(bool inPin)
    {
        if (!inPin || pthread_getaffinity_np(pthread_self(), sizeof(mOld), &mOld) != 0) return;
        for (int core = 0; core < CPU_SETSIZE; ++core)
            if (CPU_ISSET(core, &mOld))
            {
                cpu_set_t one;
                CPU_ZERO(&one);
                CPU_SET(core, &one);
                mPinned = pthread_setaffinity_np(pthread_self(), sizeof(one), &one) == 0;
                return;
            }
    }
    ~PinnedThread()
    {
        if (mPinned) (void)pthread_setaffinity_np(pthread_self(), sizeof(mOld), &mOld);
    }
    PinnedThread(const PinnedThread&) = delete;
    PinnedThread& operator=(const PinnedThread&) = delete;

private:
    cpu_set_t mOld;
    bool mPinned = false;
};

} // namespace cairn::tools
