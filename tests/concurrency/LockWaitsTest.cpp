// LockWaits: a lock that is free adds nothing to the thread's wait total; a lock that another thread holds
// adds the time the waiter spent blocked. The checks compare the counted wait with the window from just
// before the waiter's lock call to the holder's release (about cHold): at least half of it, so that a waiter
// that loses its core for a while right before it locks (a loaded machine, TSan) does not fail the test,
// while a wait that is not counted at all always does.

#include "cairn/physics/LockWaits.h"

#include "broadphase/BroadPhaseBruteForce.h"
#include "broadphase/BroadPhaseGlobalMutex.h"
#include "broadphase/StripedSharedMutex.h"
#include "broadphase/WriterFairSharedMutex.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/body/BodyLock.h"
#include "cairn/physics/body/BodyManager.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "common/MakePhysicsSystem.h"

#include <atomic>
#include <chrono>
#include <gtest/gtest.h>
#include <memory>
#include <thread>

namespace cairn
{
using namespace cairn::physics;
namespace
{

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
constexpr auto cHold = 30ms; ///< How long a holder keeps its lock once the waiter is on its way

/// A waiter's counted wait and the window in which it could have waited (its lock call to the release).
struct CountedWait
{
    uint64_t mCounted = 0;   ///< Of the kind of lock it waited for
    uint64_t mOtherKind = 0; ///< Of the other kind: none
    int64_t mWindowNs = 0;
};

/// Expects most of the window counted (see the file comment).
void ExpectMostOfWindow(const CountedWait& inWait)
{
    EXPECT_GT(inWait.mWindowNs, 0); // The waiter came before the release: it had to wait
    EXPECT_EQ(inWait.mOtherKind, 0u);
    EXPECT_GE(2 * int64_t(inWait.mCounted), inWait.mWindowNs)
        << "counted " << inWait.mCounted << " ns of a " << inWait.mWindowNs << " ns window";
}

/// Runs inWaiter on a second thread while this thread holds a lock (inHold takes it and returns a release
/// callable) of inKind. The holder lets go cHold after the waiter says it is about to lock.
template <class Hold, class Waiter>
CountedWait WaitBehindHolder(LockKind inKind, Hold&& inHold, Waiter&& inWaiter)
{
    std::atomic<bool> aboutToLock{false};
    CountedWait result;
    Clock::time_point lockCall;
    auto release = inHold();
    std::thread waiter(
        [&]
        {
            const LockKind other = inKind == LockKind::Body ? LockKind::BroadPhase : LockKind::Body;
            const uint64_t before = GetThisThreadLockWaitNanoseconds(inKind);
            const uint64_t otherBefore = GetThisThreadLockWaitNanoseconds(other);
            lockCall = Clock::now();
            aboutToLock.store(true, std::memory_order_release); // Release: publishes lockCall
            inWaiter();
            result.mCounted = GetThisThreadLockWaitNanoseconds(inKind) - before;
            result.mOtherKind = GetThisThreadLockWaitNanoseconds(other) - otherBefore;
        });
    while (!aboutToLock.load(std::memory_order_acquire)) // Acquire: pairs with the store above
        std::this_thread::yield();
    std::this_thread::sleep_for(cHold);
    const Clock::time_point releasedAt = Clock::now();
    release();
    waiter.join();
    result.mWindowNs = std::chrono::duration_cast<std::chrono::nanoseconds>(releasedAt - lockCall).count();
    return result;
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
    const CountedWait waited = WaitBehindHolder(
        LockKind::Body,
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
    ExpectMostOfWindow(waited);
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
    const CountedWait waited = WaitBehindHolder(
        LockKind::Body,
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
    ExpectMostOfWindow(waited);
}

TEST(LockWaitsTest, WriterFairMutexCountsBothSides)
{
    WriterFairSharedMutex mutex;
    // A writer behind a reader
    ExpectMostOfWindow(WaitBehindHolder(
        LockKind::BroadPhase,
        [&]
        {
            mutex.lock_shared();
            return [&] { mutex.unlock_shared(); };
        },
        [&]
        {
            mutex.lock();
            mutex.unlock();
        }));
    // A reader behind a writer
    ExpectMostOfWindow(WaitBehindHolder(
        LockKind::BroadPhase,
        [&]
        {
            mutex.lock();
            return [&] { mutex.unlock(); };
        },
        [&]
        {
            mutex.lock_shared();
            mutex.unlock_shared();
        }));
}

TEST(LockWaitsTest, StripedMutexCountsBothSides)
{
    StripedSharedMutex mutex;
    // A modifier (shared) behind a rebuild commit (exclusive)
    ExpectMostOfWindow(WaitBehindHolder(
        LockKind::BroadPhase,
        [&]
        {
            mutex.lock();
            return [&] { mutex.unlock(); };
        },
        [&] { StripedSharedMutex::SharedLock shared(mutex); }));
    // A commit behind a modifier
    ExpectMostOfWindow(WaitBehindHolder(
        LockKind::BroadPhase,
        [&]
        {
            const uint32_t stripe = mutex.LockShared();
            return [&mutex, stripe] { mutex.UnlockShared(stripe); };
        },
        [&]
        {
            mutex.lock();
            mutex.unlock();
        }));
}

TEST(LockWaitsTest, WriterFairMutexTriesFailBehindAWaitingWriterAndAReader)
{
    WriterFairSharedMutex mutex;
    mutex.lock_shared();
    EXPECT_FALSE(mutex.try_lock()); // A reader is inside
    std::thread writer(
        [&]
        {
            mutex.lock(); // Waits for the reader, holding the turnstile
            mutex.unlock();
        });
    // Once the writer waits, new readers may not pass it (until then a try may still succeed)
    bool refused = false;
    for (int attempt = 0; attempt < 100'000 && !refused; ++attempt)
    {
        if (mutex.try_lock_shared())
            mutex.unlock_shared();
        else
            refused = true;
        std::this_thread::yield();
    }
    EXPECT_TRUE(refused);
    mutex.unlock_shared();
    writer.join();
    EXPECT_TRUE(mutex.try_lock_shared()); // Free again
    mutex.unlock_shared();
}

/// A system with a few boxes resting on the ground, in inMode.
std::unique_ptr<PhysicsSystem> MakeSystem(BroadPhaseType inMode, BodyID& outBox)
{
    PhysicsSettings settings;
    settings.mBroadPhase = inMode;
    std::unique_ptr<PhysicsSystem> system = test::MakePhysicsSystem(settings);
    BodyCreationSettings ground;
    ground.mShape = BoxShape::Create(Vec3(20.0f, 0.5f, 20.0f)).Value();
    ground.mPosition = Vec3(0.0f, -0.5f, 0.0f);
    ground.mMotionType = MotionType::Static;
    (void)system->GetBodyInterface().CreateAndAddBody(ground, Activation::DontActivate).Value();
    BodyCreationSettings box;
    box.mShape = BoxShape::Create(Vec3(0.4f, 0.4f, 0.4f)).Value();
    for (int i = 0; i < 4; ++i)
    {
        box.mPosition = Vec3(float(i), 0.5f, 0.0f);
        outBox = system->GetBodyInterface().CreateAndAddBody(box, Activation::Activate).Value();
    }
    return system;
}

TEST(LockWaitsTest, StepStatisticsCountTheUpdatesWaits)
{
    BodyID box;
    const std::unique_ptr<PhysicsSystem> system = MakeSystem(BroadPhaseType::QuadTree, box);
    ASSERT_TRUE(system->Update(1.0f / 60.0f));
    EXPECT_EQ(system->GetLastStepStatistics().mLockWaitMs, 0.0); // Nobody else holds a lock

    // Another thread holds a body's lock when the update starts: the update waits for it at its start
    std::atomic<bool> held{false};
    Clock::time_point releasedAt;
    std::thread holder(
        [&]
        {
            BodyLockWrite lock(system->GetBodyManager(), box);
            EXPECT_NE(lock.GetBody(), nullptr);
            held.store(true, std::memory_order_release); // Release: a signal only
            std::this_thread::sleep_for(cHold);
            releasedAt = Clock::now();
        });
    while (!held.load(std::memory_order_acquire)) // Acquire: pairs with the store above
        std::this_thread::yield();
    const Clock::time_point updateCall = Clock::now();
    EXPECT_TRUE(system->Update(1.0f / 60.0f)); // Not ASSERT: the holder must be joined
    holder.join();
    CountedWait waited;
    waited.mCounted = uint64_t(system->GetLastStepStatistics().mLockWaitMs * 1.0e6);
    waited.mWindowNs = std::chrono::duration_cast<std::chrono::nanoseconds>(releasedAt - updateCall).count();
    ExpectMostOfWindow(waited);
}

/// Runs one update while another thread sits in a broad-phase query (its visitor sleeps cHold); returns the
/// update's counted wait and the window in which it could have waited.
CountedWait UpdateBesideASlowQuery(PhysicsSystem& ioSystem)
{
    std::atomic<bool> inQuery{false};
    Clock::time_point queryEnd;
    std::thread reader(
        [&]
        {
            bool first = true;
            ioSystem.GetBroadPhase().CollideAABox(AABB(Vec3::Constant(-50.0f), Vec3::Constant(50.0f)), {},
                                                  [&](BodyID)
                                                  {
                                                      if (!first) return;
                                                      first = false;
                                                      // Release: a signal only
                                                      inQuery.store(true, std::memory_order_release);
                                                      std::this_thread::sleep_for(cHold);
                                                      queryEnd = Clock::now();
                                                  });
        });
    while (!inQuery.load(std::memory_order_acquire)) // Acquire: pairs with the store above
        std::this_thread::yield();
    const Clock::time_point updateCall = Clock::now();
    EXPECT_TRUE(ioSystem.Update(1.0f / 60.0f));
    reader.join();
    CountedWait waited;
    waited.mCounted = uint64_t(ioSystem.GetLastStepStatistics().mLockWaitMs * 1.0e6);
    waited.mWindowNs = std::chrono::duration_cast<std::chrono::nanoseconds>(queryEnd - updateCall).count();
    return waited;
}

TEST(LockWaitsTest, GlobalMutexUpdateWaitsForAQueryAndCountsIt)
{
    // The "before" mode: the update takes the broad phase's mutex exclusively, behind the query's shared hold
    BodyID box;
    const std::unique_ptr<PhysicsSystem> system = MakeSystem(BroadPhaseType::QuadTreeGlobalMutex, box);
    ExpectMostOfWindow(UpdateBesideASlowQuery(*system));
}

TEST(LockWaitsTest, GlobalMutexQueryWaitsForAnExclusiveHoldAndCountsIt)
{
    // The wrapper alone, around another broad phase: a query waits while a thread is in an exclusive section
    // (as it would behind a modification), and the wait is a broad-phase wait
    BroadPhaseGlobalMutex broadPhase(std::make_unique<BroadPhaseBruteForce>());
    std::atomic<bool> inside{false}, letGo{false};
    std::thread holder;
    ExpectMostOfWindow(WaitBehindHolder(
        LockKind::BroadPhase,
        [&]
        {
            holder = std::thread(
                [&]
                {
                    broadPhase.WithExclusiveLock(
                        [&](BroadPhase&)
                        {
                            inside.store(true, std::memory_order_release); // Release: a signal only
                            // Acquire: pairs with the store below
                            while (!letGo.load(std::memory_order_acquire))
                                std::this_thread::yield();
                        });
                });
            while (!inside.load(std::memory_order_acquire)) // Acquire: pairs with the store above
                std::this_thread::yield();
            return [&]
            {
                letGo.store(true, std::memory_order_release); // Release: a signal only
                holder.join();
            };
        },
        [&] { broadPhase.CollideAABox(AABB(Vec3::Zero(), Vec3::Ones()), {}, [](BodyID) {}); }));
}

TEST(LockWaitsTest, LockFreeUpdateNeverWaitsForAQuery)
{
    BodyID box;
    const std::unique_ptr<PhysicsSystem> system = MakeSystem(BroadPhaseType::QuadTree, box);
    EXPECT_EQ(UpdateBesideASlowQuery(*system).mCounted, 0u);
}

} // namespace
} // namespace cairn
