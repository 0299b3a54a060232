// Two agent profiles on one physics world: a human (radius 0.6 m) and a large agent (1.5 m), each with its
// own navmesh built by the same tile pipeline from the same bodies and its own crowd. A wall with a 2 m gap
// lets the human through and not the large agent, which goes as far as its navmesh reaches and stops there.

#include "NavMeshSceneFixture.h"
#include "cairn/jobs/BackgroundQueue.h"
#include "cairn/navmesh/Crowd.h"
#include "cairn/navmesh/TileScheduler.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "common/MakePhysicsSystem.h"

#include <chrono>
#include <gtest/gtest.h>
#include <thread>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

/// A profile's navmesh over 2 x 2 tiles each side of the origin, built from inPhysics by its own scheduler.
struct ProfileNavMesh
{
    ProfileNavMesh(PhysicsSystem& ioPhysics, const AgentProfile& inProfile)
    {
        const float half = 2.0f * inProfile.mTileSize;
        mWorld = NavMeshWorld::Create(TileGrid(-half, -half, inProfile.mTileSize, -5.0f, 20.0f), inProfile)
                     .Value();
        jobs::BackgroundQueue::Settings settings;
        settings.mNumThreads = 1;
        mQueue = std::make_unique<jobs::BackgroundQueue>(settings);
        mScheduler = std::make_unique<TileScheduler>(ioPhysics, *mWorld, *mQueue, TileScheduler::Settings{});
        EXPECT_TRUE(mScheduler->AddArea(
            AABB(Vec3(-half + 0.1f, -5, -half + 0.1f), Vec3(half - 0.1f, 20, half - 0.1f))));
    }
    ~ProfileNavMesh() { mScheduler.reset(); } // Its jobs first

    std::unique_ptr<NavMeshWorld> mWorld;
    std::unique_ptr<jobs::BackgroundQueue> mQueue;
    std::unique_ptr<TileScheduler> mScheduler;
};

TEST(CrowdProfilesTest, EachProfileWalksItsOwnNavMesh)
{
    std::unique_ptr<PhysicsSystem> physics = cairn::test::MakePhysicsSystem();
    BodyInterface& bodies = physics->GetBodyInterface();
    auto addStatic = [&](const Vec3& inCenter, const Vec3& inHalfExtent)
    {
        BodyCreationSettings settings;
        settings.mShape = BoxShape::Create(inHalfExtent).Value();
        settings.mPosition = inCenter;
        settings.mMotionType = MotionType::Static;
        settings.mObjectLayer = Layers::cStatic;
        ASSERT_TRUE(bodies.CreateAndAddBody(settings, Activation::DontActivate).IsOk());
    };
    addStatic(Vec3(0, -0.5f, 0), Vec3(25, 0.5f, 25));
    // A wall across z = 0 from x = -25 to 25, with a 2 m gap at x in [-1, 1]
    addStatic(Vec3(-13, 1.5f, 0), Vec3(12, 1.5f, 0.3f));
    addStatic(Vec3(13, 1.5f, 0), Vec3(12, 1.5f, 0.3f));

    AgentProfile human, large;
    large.mRadius = 1.5f;
    ProfileNavMesh humanMesh(*physics, human), largeMesh(*physics, large);
    const auto deadline = std::chrono::steady_clock::now() + cIdleTimeout; // See there
    while (std::chrono::steady_clock::now() < deadline &&
           !(humanMesh.mScheduler->IsIdle() && largeMesh.mScheduler->IsIdle()))
    {
        humanMesh.mScheduler->Update();
        largeMesh.mScheduler->Update();
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    humanMesh.mScheduler->Update();
    largeMesh.mScheduler->Update();
    ASSERT_GT(humanMesh.mWorld->GetNumTiles(), 0);
    ASSERT_GT(largeMesh.mWorld->GetNumTiles(), 0);

    Crowd::Settings settings;
    std::unique_ptr<Crowd> humans = Crowd::Create(*humanMesh.mWorld, settings).Value();
    std::unique_ptr<Crowd> larges = Crowd::Create(*largeMesh.mWorld, settings).Value();
    AgentParams largeParams;
    largeParams.mRadius = 1.5f;
    const Vec3 start(0, 0, -10), goal(0, 0, 10);
    const Crowd::AgentID person = humans->AddAgent(start).Value();
    const Crowd::AgentID giant = larges->AddAgent(start, largeParams).Value();
    ASSERT_TRUE(humans->SetTarget(person, goal).IsOk());
    ASSERT_TRUE(larges->SetTarget(giant, goal).IsOk());
    for (int frame = 0; frame < 900; ++frame)
    {
        ASSERT_TRUE(humans->Update(1.0f / 60.0f).IsOk());
        ASSERT_TRUE(larges->Update(1.0f / 60.0f).IsOk());
    }
    EXPECT_EQ(humans->GetState(person).Value(), AgentState::Arrived);
    EXPECT_NEAR(humans->GetPosition(person).Value().z(), goal.z(), 1.0f) << "through the gap";
    // The large agent's navmesh keeps 1.5 m from the wall: no way through the 2 m gap; it stops on its side
    const Result<PathResult> largePath = largeMesh.mWorld->FindPath(start, goal);
    ASSERT_TRUE(largePath);
    EXPECT_FALSE(largePath.Value().mReachedEnd) << "the gap is too narrow for the large profile's navmesh";
    EXPECT_TRUE(humanMesh.mWorld->FindPath(start, goal).Value().mReachedEnd);
    EXPECT_LT(larges->GetPosition(giant).Value().z(), -0.3f - 1.5f + 0.2f) << "stays on its side of the wall";
}

} // namespace
} // namespace cairn::navmesh::test
