// LockWaits: a lock that is free adds nothing to the thread's wait total; a lock that another thread holds
// adds at least the time it was held after the waiter arrived. The holders below keep their lock for a fixed
// sleep after the waiter announced itself, so the lower bounds hold on any machine (sleeps only overshoot).

#include "cairn/physics/LockWaits.h"

#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/body/BodyLock.h"
#include "cairn/physics/body/BodyManager.h"
#include "cairn/physics/broadphase/StripedSharedMutex.h"
#include "cairn/physics/broadphase/WriterFairSharedMutex.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"

#include <atomic>
#include <chrono>
#include <gtest/gtest.h>
#include <thread>

namespace cairn
{
namespace
{

using namespace std::chrono_literals;
constexpr auto cHold = 30ms; ///< How long a holder keeps its lock once the waiter is on its way
constexpr uint64_t cMinWaitNs =
    20'000'000; ///< What the waiter must have counted at least (cHold, less slack)

/// Runs inWaiter on a second thread while this thread holds a lock (inHold takes it and returns a release
/// callable); returns the waiter's counted wait. The holder sleeps cHold after the waiter says it is about to
/// lock, so the waiter blocks for about cHold.
template <class Hold, class Waiter> uint64_t WaitBehindHolder(Hold&& inHold, Waiter&& inWaiter)
{
    std::atomic<bool> aboutToLock{false};
    uint64_t waited = 0;
    auto release = inHold();
    std::thread waiter(
        [&]
        {
            const uint64_t before = GetThisThreadLockWaitNanoseconds();
            aboutToLock.store(true, std::memory_order_release); // Release: nothing to publish, a signal only
            inWaiter();
            waited = GetThisThreadLockWaitNanoseconds() - before;
        });
    while (!aboutToLock.load(std::memory_order_acquire)) // Acquire: pairs with the store above
        std::this_thread::yield();
    std::this_thread::sleep_for(cHold);
    release();
    waiter.join();
    return waited;
}

BodyID MakeBody(BodyManager& ioManager)
{
    BodyCreationSettings settings;
    settings.mShape = SphereShape::Create(0.5f).Value();
    settings.mMotionType = MotionType::Dynamic;
    return ioManager.CreateBody(settings).Value();
}

TEST(LockWaitsTest, FreeLocksCountNothing)
{
    BodyManager manager(16);
    const BodyID body = MakeBody(manager);
    WriterFairSharedMutex fair;
    StripedSharedMutex striped;
    const uint64_t before = GetThisThreadLockWaitNanoseconds();
    for (int i = 0; i < 1000; ++i)
    {
        {
            BodyLockRead read(manager, body);
            ASSERT_NE(read.GetBody(), nullptr);
        }
        {
            BodyLockWrite write(manager, body);
            ASSERT_NE(write.GetBody(), nullptr);
        }
        {
            StaticBodyLockRead read(manager, body);
            EXPECT_TRUE(read.WasNotStatic());
        }
        fair.lock_shared();
        fair.unlock_shared();
        fair.lock();
        fair.unlock();
        {
            StripedSharedMutex::SharedLock shared(striped);
        }
        striped.lock();
        striped.unlock();
    }
    EXPECT_EQ(GetThisThreadLockWaitNanoseconds(), before);
}

TEST(LockWaitsTest, ReaderCountsItsWaitForABodyWriter)
{
    BodyManager manager(16);
    const BodyID body = MakeBody(manager);
    const uint64_t holderBefore = GetThisThreadLockWaitNanoseconds();
    const uint64_t waited = WaitBehindHolder(
        [&]
        {
            auto lock = std::make_shared<BodyLockWrite>(manager, body);
            EXPECT_NE(lock->GetBody(), nullptr);
            return [lock]() mutable { lock->Release(); };
        },
        [&]
        {
            BodyLockRead read(manager, body);
            EXPECT_NE(read.GetBody(), nullptr);
        });
    EXPECT_GE(waited, cMinWaitNs);
    EXPECT_EQ(GetThisThreadLockWaitNanoseconds(), holderBefore); // The holder itself never waited
}

TEST(LockWaitsTest, WriterCountsItsWaitForAStaticReader)
{
    // A tile job's read of a static body keeps out a writer of that body (the static mutex)
    BodyManager manager(16);
    BodyCreationSettings settings;
    settings.mShape = SphereShape::Create(0.5f).Value();
    settings.mMotionType = MotionType::Static;
    const BodyID body = manager.CreateBody(settings).Value();
    const uint64_t waited = WaitBehindHolder(
        [&]
        {
            auto lock = std::make_shared<StaticBodyLockRead>(manager, body);
            EXPECT_NE(lock->GetBody(), nullptr);
            return [lock]() mutable { lock->Release(); };
        },
        [&]
        {
            BodyLockWrite write(manager, body);
            EXPECT_NE(write.GetBody(), nullptr);
        });
    EXPECT_GE(waited, cMinWaitNs);
}

TEST(LockWaitsTest, WriterFairMutexCountsBothSides)
{
    WriterFairSharedMutex mutex;
    // A writer behind a reader
    EXPECT_GE(WaitBehindHolder(
                  [&]
                  {
                      mutex.lock_shared();
                      return [&] { mutex.unlock_shared(); };
                  },
                  [&]
                  {
                      mutex.lock();
                      mutex.unlock();
                  }),
              cMinWaitNs);
    // A reader behind a writer
    EXPECT_GE(WaitBehindHolder(
                  [&]
                  {
                      mutex.lock();
                      return [&] { mutex.unlock(); };
                  },
                  [&]
                  {
                      mutex.lock_shared();
                      mutex.unlock_shared();
                  }),
              cMinWaitNs);
}

TEST(LockWaitsTest, StripedMutexCountsBothSides)
{
    StripedSharedMutex mutex;
    // A modifier (shared) behind a rebuild commit (exclusive)
    EXPECT_GE(WaitBehindHolder(
                  [&]
                  {
                      mutex.lock();
                      return [&] { mutex.unlock(); };
                  },
                  [&] { StripedSharedMutex::SharedLock shared(mutex); }),
              cMinWaitNs);
    // A commit behind a modifier
    EXPECT_GE(WaitBehindHolder(
                  [&]
                  {
                      const uint32_t stripe = mutex.LockShared();
                      return [&mutex, stripe] { mutex.UnlockShared(stripe); };
                  },
                  [&]
                  {
                      mutex.lock();
                      mutex.unlock();
                  }),
              cMinWaitNs);
}

TEST(LockWaitsTest, StepStatisticsCountTheUpdatesWaits)
{
    PhysicsSystem system;
    BodyCreationSettings box;
    box.mShape = BoxShape::Create(Vec3(0.4f, 0.4f, 0.4f)).Value();
    const BodyID body = system.GetBodyInterface().CreateAndAddBody(box, Activation::Activate).Value();
    ASSERT_TRUE(system.Update(1.0f / 60.0f));
    EXPECT_EQ(system.GetLastStepStatistics().mLockWaitMs, 0.0); // Nobody else holds a lock

    // Another thread holds the body's lock when the update starts: the update waits for it at its start
    std::atomic<bool> held{false};
    std::thread holder(
        [&]
        {
            BodyLockWrite lock(system.GetBodyManager(), body);
            EXPECT_NE(lock.GetBody(), nullptr);
            held.store(true, std::memory_order_release); // Release: a signal only
            std::this_thread::sleep_for(cHold);
        });
    while (!held.load(std::memory_order_acquire)) // Acquire: pairs with the store above
        std::this_thread::yield();
    EXPECT_TRUE(system.Update(1.0f / 60.0f)); // Not ASSERT: the holder must be joined
    holder.join();
    // Most of cHold, less what it took this thread to get to the lock
    EXPECT_GE(system.GetLastStepStatistics().mLockWaitMs, 10.0);
}

} // namespace
} // namespace cairn
