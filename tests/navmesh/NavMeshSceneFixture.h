#pragma once

// A physics world with a navmesh kept up to date in the background: the fixture of the navmesh scene tests.
// Frame() is one game frame: a physics step, then the scheduler's Update (the sync point).

#include "cairn/jobs/BackgroundQueue.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/navmesh/TileScheduler.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "common/MakePhysicsSystem.h"

#include <chrono>
#include <gtest/gtest.h>
#include <memory>
#include <thread>

namespace cairn::navmesh::test
{
using namespace cairn::physics;

/// A bound on waiting for background tile builds, against a hang only, never a speed check: on a loaded
/// machine (ctest -j2 on CI's 2 cores, a build beside it) the one background thread gets a fraction of a
/// core, and a bound of 2,000 frames of 1 ms let a 64-tile town's first build fail.
inline constexpr std::chrono::seconds cIdleTimeout{120};

class NavMeshSceneFixture : public ::testing::Test
{
protected:
    /// inTilesPerSide tiles of 12.8 m on each side of the origin.
    void MakeNavMesh(int inTilesPerSide = 1, TileScheduler::Settings inSettings = {})
    {
        const AgentProfile profile;
        const float half = float(inTilesPerSide) * profile.mTileSize;
        const TileGrid grid(-half, -half, profile.mTileSize, -5.0f, 20.0f);
        mWorld = std::move(NavMeshWorld::Create(grid, profile).Value());
        jobs::BackgroundQueue::Settings queueSettings;
        queueSettings.mNumThreads = 1;
        mQueue = std::make_unique<jobs::BackgroundQueue>(queueSettings);
        mScheduler = std::make_unique<TileScheduler>(*mPhysics, *mWorld, *mQueue, inSettings);
        mArea = mScheduler
                    ->AddArea(AABB(Vec3(-half + 0.1f, -5, -half + 0.1f), Vec3(half - 0.1f, 20, half - 0.1f)))
                    .Value();
    }

    void TearDown() override
    {
        mScheduler.reset(); // Before the physics world its jobs read
    }

    BodyID AddStaticBox(const Vec3& inCenter, const Vec3& inHalfExtent, uint8_t inArea = 0)
    {
        BodyCreationSettings settings;
        settings.mShape = BoxShape::Create(inHalfExtent).Value();
        settings.mPosition = inCenter;
        settings.mMotionType = MotionType::Static;
        settings.mObjectLayer = Layers::cStatic;
        settings.mNavMeshArea = inArea;
        return mPhysics->GetBodyInterface().CreateAndAddBody(settings, Activation::DontActivate).Value();
    }

    BodyID AddDynamicBox(const Vec3& inCenter, const Vec3& inHalfExtent)
    {
        BodyCreationSettings settings;
        settings.mShape = BoxShape::Create(inHalfExtent).Value();
        settings.mPosition = inCenter;
        settings.mMotionType = MotionType::Dynamic;
        settings.mObjectLayer = Layers::cMoving;
        return mPhysics->GetBodyInterface().CreateAndAddBody(settings, Activation::Activate).Value();
    }

    void Frame()
    {
        ASSERT_TRUE(mPhysics->Update(1.0f / 60.0f).IsOk());
        mScheduler->Update();
    }

    /// Frames until the scheduler is idle (every needed tile built and published); false after inTimeout.
    bool RunUntilIdle(std::chrono::seconds inTimeout = cIdleTimeout)
    {
        const auto deadline = std::chrono::steady_clock::now() + inTimeout;
        while (std::chrono::steady_clock::now() < deadline)
        {
            Frame();
            if (mScheduler->IsIdle())
            {
                mScheduler->Update(); // Publishes what the last jobs handed in
                return true;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(1)); // Let the tile jobs run
        }
        return false;
    }

    std::unique_ptr<PhysicsSystem> mPhysics = cairn::test::MakePhysicsSystem();
    std::unique_ptr<NavMeshWorld> mWorld;
    std::unique_ptr<jobs::BackgroundQueue> mQueue;
    std::unique_ptr<TileScheduler> mScheduler;
    TileScheduler::AreaID mArea = 0;
};

} // namespace cairn::navmesh::test
