// A colored island (a pyramid of boxes on a floor, one island of a few hundred contacts) solved by every
// thread of the job system at once: the colors' stages synchronise on counters, the parts of a color go to
// whichever thread takes them first. And small islands solved four at a time, groups on all threads; and
// several colored islands too small to need every thread, each solved by one thread at once. Under
// ThreadSanitizer (this suite's label) that must show no race, and with 2 and 4 threads the bodies must end
// exactly where one thread puts them.

#include "cairn/jobs/JobSystem.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "common/StaticFloor.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <memory>
#include <vector>

namespace cairn
{
namespace
{

struct Pose
{
    Vec3 mPosition;
    Vec3 mVelocity;
};

enum class Scene
{
    Pyramid,        ///< One 7-layer pyramid (140 boxes, slightly turned so contacts have 1 to 4 points)
    SmallStacks,    ///< 40 stacks of one to three boxes (islands of up to four constraints)
    SeveralPyramids ///< Six 5-layer pyramids apart: six colored islands, each under a quarter of the step
};

/// Steps inScene on inThreads job threads (0: none) and returns the boxes' final positions and velocities;
/// outStats: the last step's statistics.
std::vector<Pose> StepScene(Scene inScene, uint32_t inThreads, int inSteps, StepStatistics& outStats)
{
    std::unique_ptr<jobs::JobSystem> jobSystem;
    if (inThreads > 0) jobSystem = std::make_unique<jobs::JobSystem>(jobs::JobSystem::Settings{inThreads});
    PhysicsSettings settings;
    settings.mAllowSleeping = false;
    PhysicsSystem system(settings);
    BodyInterface& bodies = system.GetBodyInterface();
    const BodyCreationSettings floor = test::StaticFloorSettings(30.0f);
    EXPECT_TRUE(bodies.CreateAndAddBody(floor, Activation::DontActivate).IsOk());
    const ShapeRef box = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    std::vector<BodyID> boxes;
    for (int i = 0; inScene == Scene::SmallStacks && i < 40; ++i)
        for (int level = 0; level <= i % 3; ++level)
        {
            BodyCreationSettings body;
            body.mShape = box;
            body.mPosition =
                Vec3(-25.0f + 2.5f * float(i % 20), 0.6f + 1.1f * float(level), 3.0f * float(i / 20));
            body.mRotation = Quat(Eigen::AngleAxisf(0.3f * float(i % 4), Vec3::UnitY()));
            body.mObjectLayer = Layers::cMoving;
            boxes.push_back(bodies.CreateAndAddBody(body, Activation::Activate).Value());
        }
    const int numPyramids = inScene == Scene::Pyramid ? 1 : inScene == Scene::SeveralPyramids ? 6 : 0;
    const int layers = inScene == Scene::Pyramid ? 7 : 5;
    for (int pyramid = 0; pyramid < numPyramids; ++pyramid)
        for (int layer = 0; layer < layers; ++layer)
            for (int i = 0; i < layers - layer; ++i)
                for (int k = 0; k < layers - layer; ++k)
                {
                    BodyCreationSettings body;
                    body.mShape = box;
                    body.mPosition = Vec3(float(i) + 0.5f * float(layer) + 8.0f * float(pyramid % 3) - 12.0f,
                                          0.5f + 1.05f * float(layer),
                                          float(k) + 0.5f * float(layer) + 8.0f * float(pyramid / 3));
                    body.mRotation = Quat(Eigen::AngleAxisf(0.02f * float(i + k), Vec3::UnitY()));
                    body.mObjectLayer = Layers::cMoving;
                    body.mFriction = 0.6f;
                    boxes.push_back(bodies.CreateAndAddBody(body, Activation::Activate).Value());
                }
    for (int step = 0; step < inSteps; ++step)
        EXPECT_TRUE(
            (jobSystem ? system.Update(1.0f / 60.0f, 1, *jobSystem) : system.Update(1.0f / 60.0f)).IsOk());
    outStats = system.GetLastStepStatistics();
    std::vector<Pose> poses;
    for (const BodyID& id : boxes)
        poses.push_back({bodies.GetPosition(id).Value(), bodies.GetLinearVelocity(id).Value()});
    return poses;
}

/// Steps inScene without a job system and returns the last step's statistics; expects the same poses on 2
/// and 4 job threads.
StepStatistics ExpectSameOnTwoAndFourThreads(Scene inScene)
{
    constexpr int cSteps = 40;
    StepStatistics stats;
    const std::vector<Pose> reference = StepScene(inScene, 0, cSteps, stats);
    for (uint32_t threads : {2u, 4u})
    {
        StepStatistics unused;
        const std::vector<Pose> poses = StepScene(inScene, threads, cSteps, unused);
        EXPECT_EQ(poses.size(), reference.size());
        for (size_t i = 0; i < std::min(poses.size(), reference.size()); ++i)
        {
            // == rather than a bit compare: an impulse of zero may turn a -0 velocity into +0
            EXPECT_TRUE(poses[i].mPosition == reference[i].mPosition &&
                        poses[i].mVelocity == reference[i].mVelocity)
                << "box " << i << " with " << threads << " threads: " << poses[i].mPosition.transpose()
                << " against " << reference[i].mPosition.transpose();
        }
    }
    return stats;
}

TEST(ColoredIslandThreadsTest, SameResultOnOneTwoAndFourThreads)
{
    const StepStatistics stats = ExpectSameOnTwoAndFourThreads(Scene::Pyramid);
    // Large enough to be colored (PhysicsStep colors islands of 128 constraints and more)
    EXPECT_EQ(stats.mNumIslands, 1u);
    EXPECT_GE(stats.mNumManifolds, 128u) << "the pyramid was not one colored island";
}

TEST(ColoredIslandThreadsTest, SmallIslandGroupsSameResultOnOneTwoAndFourThreads)
{
    const StepStatistics stats = ExpectSameOnTwoAndFourThreads(Scene::SmallStacks);
    EXPECT_GE(stats.mNumIslands, 20u) << "the stacks were not separate small islands";
}

TEST(ColoredIslandThreadsTest, IslandsSolvedAloneSameResultOnOneTwoAndFourThreads)
{
    const StepStatistics stats = ExpectSameOnTwoAndFourThreads(Scene::SeveralPyramids);
    // Six islands of 128 constraints or more (colored), each under a quarter of the step's constraints: each
    // is solved by one thread, several at once
    EXPECT_EQ(stats.mNumIslands, 6u);
    EXPECT_GE(stats.mNumManifolds, 6u * 128u);
}

} // namespace
} // namespace cairn
