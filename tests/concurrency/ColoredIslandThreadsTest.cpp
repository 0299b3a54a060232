// A colored island (a pyramid of boxes on a floor, one island of a few hundred contacts) solved by every
// thread of the job system at once: the colors' stages synchronise on each part's progress, the parts of a
// color go to whichever thread takes them first. And small islands solved four at a time, groups on all
// threads; and several colored islands too small to need every thread, each solved by one thread at once; and
// jointed islands colored with their joints (a pile of ragdolls; a hub whose joints overflow the colors).
// Under ThreadSanitizer (this suite's label) that must show no race, and with 2 and 4 threads the bodies must
// end exactly where one thread puts them.

#include "cairn/jobs/JobSystem.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/ragdoll/HumanoidRagdoll.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "common/MakePhysicsSystem.h"
#include "common/StaticFloor.h"

#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>
#include <memory>
#include <numbers>
#include <thread>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

struct Pose
{
    Vec3 mPosition;
    Vec3 mVelocity;
};

enum class Scene
{
    Pyramid,         ///< One 7-layer pyramid (140 boxes, slightly turned so contacts have 1 to 4 points)
    SmallStacks,     ///< 40 stacks of one to three boxes (islands of up to four constraints)
    SeveralPyramids, ///< Six 5-layer pyramids apart, a bouncy ball on each: six colored islands, each under a
                     ///< quarter of the step
    LoadedPlank, ///< 144 boxes on one dynamic plank: its 145 contacts cannot all take one of the 64 colors
    RagdollPile, ///< Six humanoid ragdolls dropped onto each other: one island of 132 joints and the contacts
    JointedHub   ///< 160 balls each jointed to one hub: joints that cannot all take one of the 64 colors
};

struct SceneWorld
{
    std::unique_ptr<PhysicsSystem> mSystem;
    std::vector<BodyID> mBoxes;
};

SceneWorld MakeScene(Scene inScene)
{
    PhysicsSettings settings;
    settings.mAllowSleeping = false;
    SceneWorld world{test::MakePhysicsSystem(settings), {}};
    BodyInterface& bodies = world.mSystem->GetBodyInterface();
    std::vector<BodyID>& boxes = world.mBoxes;
    const BodyCreationSettings floor = test::StaticFloorSettings(30.0f);
    EXPECT_TRUE(bodies.CreateAndAddBody(floor, Activation::DontActivate).IsOk());
    const ShapeRef box = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
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
    // The plank shares a body with every one of its contacts, so each needs a color of its own: the 81 that
    // find none of the 64 free form the island's serial range, solved by one thread in the solve order
    if (inScene == Scene::LoadedPlank)
    {
        BodyCreationSettings plank;
        plank.mShape = BoxShape::Create(Vec3(8.0f, 0.25f, 8.0f)).Value();
        plank.mPosition = Vec3(0.0f, 0.25f, 0.0f);
        plank.mObjectLayer = Layers::cMoving;
        boxes.push_back(bodies.CreateAndAddBody(plank, Activation::Activate).Value());
        for (int i = 0; i < 12; ++i)
            for (int k = 0; k < 12; ++k)
            {
                BodyCreationSettings body;
                body.mShape = box;
                body.mPosition = Vec3(-6.6f + 1.2f * float(i), 1.0f, -6.6f + 1.2f * float(k));
                body.mObjectLayer = Layers::cMoving;
                boxes.push_back(bodies.CreateAndAddBody(body, Activation::Activate).Value());
            }
    }
    // A bouncy ball dropped onto each of the six pyramids: their islands (solved alone) take the restitution
    // pass, with the impulses unpacked from the batches
    const ShapeRef ball = SphereShape::Create(0.3f).Value();
    for (int pyramid = 0; inScene == Scene::SeveralPyramids && pyramid < numPyramids; ++pyramid)
    {
        BodyCreationSettings body;
        body.mShape = ball;
        body.mPosition =
            Vec3(2.0f + 8.0f * float(pyramid % 3) - 12.0f, 6.0f, 2.0f + 8.0f * float(pyramid / 3));
        body.mObjectLayer = Layers::cMoving;
        body.mRestitution = 0.8f;
        boxes.push_back(bodies.CreateAndAddBody(body, Activation::Activate).Value());
    }
    // Ragdolls lying on their backs, each turned a little more and 0.45 m above the last
    const RagdollSettings humanoid = MakeHumanoidRagdoll();
    for (uint32_t i = 0; inScene == Scene::RagdollPile && i < 6; ++i)
    {
        const Quat lying = Quat(Eigen::AngleAxisf(0.9f * float(i), Vec3::UnitY())) *
                           Quat(Eigen::AngleAxisf(0.5f * std::numbers::pi_v<float>, Vec3::UnitZ()));
        Result<Ragdoll> ragdoll =
            Ragdoll::Create(*world.mSystem, humanoid, Vec3(0.1f * float(i), 0.5f + 0.45f * float(i), 0.0f),
                            lying, i + 1, Activation::Activate);
        EXPECT_TRUE(ragdoll.IsOk());
        if (ragdoll)
            boxes.insert(boxes.end(), ragdoll.Value().GetBodies().begin(), ragdoll.Value().GetBodies().end());
    }
    // A hub with rings of balls, each on a point joint to it: every joint shares the hub, so 64 take a color
    // each and the other 96 form the island's serial range
    if (inScene == Scene::JointedHub)
    {
        BodyCreationSettings hub;
        hub.mShape = SphereShape::Create(0.5f).Value();
        hub.mPosition = Vec3(0.0f, 6.0f, 0.0f);
        hub.mObjectLayer = Layers::cMoving;
        const BodyID hubID = bodies.CreateAndAddBody(hub, Activation::Activate).Value();
        boxes.push_back(hubID);
        for (int i = 0; i < 160; ++i)
        {
            BodyCreationSettings body;
            body.mShape = ball;
            // Five rings of 32, 0.8 m apart in height: the balls 0.69 m apart on a ring, none touching
            const float turn = 0.1963495f * float(i / 5), height = 6.0f + 0.8f * float(i % 5) - 1.6f;
            body.mPosition = Vec3(3.5f * std::cos(turn), height, 3.5f * std::sin(turn));
            body.mObjectLayer = Layers::cMoving;
            boxes.push_back(bodies.CreateAndAddBody(body, Activation::Activate).Value());
            PointConstraintSettings joint;
            joint.mBodyA = hubID;
            joint.mBodyB = boxes.back();
            joint.mPoint = 0.5f * (hub.mPosition + body.mPosition);
            EXPECT_TRUE(world.mSystem->GetConstraintInterface().AddPoint(joint).IsOk());
        }
    }
    return world;
}

/// Steps inWorld inSteps times (on ioJobs, or without a job system) and returns the boxes' final positions
/// and velocities.
std::vector<Pose> StepWorld(SceneWorld& ioWorld, jobs::JobSystem* ioJobs, int inSteps)
{
    PhysicsSystem& system = *ioWorld.mSystem;
    for (int step = 0; step < inSteps; ++step)
        EXPECT_TRUE((ioJobs ? system.Update(1.0f / 60.0f, 1, *ioJobs) : system.Update(1.0f / 60.0f)).IsOk());
    std::vector<Pose> poses;
    for (const BodyID& id : ioWorld.mBoxes)
        poses.push_back({system.GetBodyInterface().GetPosition(id).Value(),
                         system.GetBodyInterface().GetLinearVelocity(id).Value()});
    return poses;
}

/// Steps inScene on inThreads job threads (0: none) and returns the boxes' final positions and velocities;
/// outStats: the last step's statistics.
std::vector<Pose> StepScene(Scene inScene, uint32_t inThreads, int inSteps, StepStatistics& outStats)
{
    std::unique_ptr<jobs::JobSystem> jobSystem;
    if (inThreads > 0) jobSystem = std::make_unique<jobs::JobSystem>(jobs::JobSystem::Settings{inThreads});
    SceneWorld world = MakeScene(inScene);
    std::vector<Pose> poses = StepWorld(world, jobSystem.get(), inSteps);
    outStats = world.mSystem->GetLastStepStatistics();
    return poses;
}

/// Whether two runs ended with the same poses (== rather than a bit compare: an impulse of zero may turn a -0
/// velocity into +0).
void ExpectSamePoses(const std::vector<Pose>& inPoses, const std::vector<Pose>& inReference,
                     const char* inWhat)
{
    EXPECT_EQ(inPoses.size(), inReference.size());
    for (size_t i = 0; i < std::min(inPoses.size(), inReference.size()); ++i)
        EXPECT_TRUE(inPoses[i].mPosition == inReference[i].mPosition &&
                    inPoses[i].mVelocity == inReference[i].mVelocity)
            << "box " << i << " " << inWhat << ": " << inPoses[i].mPosition.transpose() << " against "
            << inReference[i].mPosition.transpose();
}

/// Steps inScene inSteps times without a job system and returns the last step's statistics; expects the same
/// poses on 2 and 4 job threads.
StepStatistics ExpectSameOnTwoAndFourThreads(Scene inScene, int inSteps = 40)
{
    StepStatistics stats;
    const std::vector<Pose> reference = StepScene(inScene, 0, inSteps, stats);
    for (uint32_t threads : {2u, 4u})
    {
        StepStatistics unused;
        ExpectSamePoses(StepScene(inScene, threads, inSteps, unused), reference,
                        threads == 2 ? "with 2 threads" : "with 4 threads");
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
    // is solved by one thread, several at once (and a ball in the air is an island of its own, without any)
    EXPECT_GE(stats.mNumIslands, 6u);
    EXPECT_LE(stats.mNumIslands, 12u);
    EXPECT_GE(stats.mNumManifolds, 6u * 128u);
}

TEST(ColoredIslandThreadsTest, JointedIslandsColoredWithTheirJointsSameResultOnOneTwoAndFourThreads)
{
    // Joints take part in the coloring (a color's joints and contacts share no dynamic body) and each part of
    // a color solves its joints, then its contacts, in the velocity and position passes
    for (const Scene scene : {Scene::RagdollPile, Scene::JointedHub})
    {
        SCOPED_TRACE(scene == Scene::RagdollPile ? "ragdoll pile" : "jointed hub");
        // The pile is one island once the ragdolls have fallen onto each other
        const StepStatistics stats =
            ExpectSameOnTwoAndFourThreads(scene, scene == Scene::RagdollPile ? 120 : 40);
        EXPECT_GE(stats.mNumColoredIslands, 1u);
    }
}

TEST(ColoredIslandThreadsTest, TwoWorldsOnOneJobSystemAtOnce)
{
    // Two worlds updated at once from two threads on one job system: a thread that waits for its own world's
    // jobs runs the other world's meanwhile. One world's island is solved by all threads, the other's islands
    // each by one thread: neither may touch the other's solver data (each world's batches are its own)
    constexpr int cSteps = 30;
    SceneWorld pyramidAlone = MakeScene(Scene::Pyramid), severalAlone = MakeScene(Scene::SeveralPyramids);
    const std::vector<Pose> pyramidReference = StepWorld(pyramidAlone, nullptr, cSteps);
    const std::vector<Pose> severalReference = StepWorld(severalAlone, nullptr, cSteps);
    jobs::JobSystem jobSystem(jobs::JobSystem::Settings{4});
    SceneWorld pyramid = MakeScene(Scene::Pyramid), several = MakeScene(Scene::SeveralPyramids);
    std::vector<Pose> pyramidPoses, severalPoses;
    std::thread other([&] { severalPoses = StepWorld(several, &jobSystem, cSteps); });
    pyramidPoses = StepWorld(pyramid, &jobSystem, cSteps);
    other.join();
    ExpectSamePoses(pyramidPoses, pyramidReference, "of the pyramid");
    ExpectSamePoses(severalPoses, severalReference, "of the six pyramids");
}

TEST(ColoredIslandThreadsTest, IslandWithAnUncoloredRangeSameResultOnOneTwoAndFourThreads)
{
    const StepStatistics stats = ExpectSameOnTwoAndFourThreads(Scene::LoadedPlank);
    EXPECT_EQ(stats.mNumIslands, 1u);
    EXPECT_GE(stats.mNumManifolds, 128u) << "the plank's island was too small to be colored";
}

} // namespace
} // namespace cairn
