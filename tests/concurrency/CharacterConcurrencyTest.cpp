// Characters walking on their own threads while the world steps on a job system, crates are added and
// removed, and an elevator rises and sinks under some of them: every Update answers, none waits for the step,
// and no character sinks through the floor or the elevator. Members of a character group, updated on two
// threads beside the step, meet without passing through each other. Part of the test command and run under
// ThreadSanitizer in CI (the concurrency label). The single-threaded behaviour is
// tests/physics/simulation/CharacterControllerTest.cpp.

#include "cairn/jobs/JobSystem.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/character/CharacterController.h"
#include "cairn/physics/character/CharacterGroup.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "common/MakePhysicsSystem.h"
#include "common/SlowBuild.h"
#include "common/StaticFloor.h"

#include <array>
#include <atomic>
#include <barrier>
#include <chrono>
#include <cmath>
#include <deque>
#include <gtest/gtest.h>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

using Clock = std::chrono::steady_clock;
constexpr float cDeltaTime = 1.0f / 60.0f;
constexpr float cHalfHeight = 0.6f, cRadius = 0.3f;
const Vec3 cGravity(0.0f, -9.81f, 0.0f);
/// The elevator: a kinematic slab at x, z in [6, 10], its top rising from 0.5 m to 2.5 m and back
constexpr float cElevatorLow = 0.25f, cElevatorRise = 2.0f;
/// How far a character's foot may be below its floor's top when checked: the elevator's rise in one step that
/// its rider has still to follow, and a margin
constexpr float cSinkTolerance = 0.05f;

TEST(CharacterConcurrencyTest, CharactersWalkOnTheirThreadsWhileTheWorldStepsAndChanges)
{
    const std::unique_ptr<PhysicsSystem> world = test::MakePhysicsSystem();
    BodyInterface& bodies = world->GetBodyInterface();
    ASSERT_TRUE(bodies.CreateAndAddBody(test::StaticFloorSettings(30.0f), Activation::DontActivate));
    const BodyID elevator =
        bodies
            .CreateAndAddBody(
                test::BoxBodySettings(Vec3(8, cElevatorLow, 8), Vec3(2, 0.25f, 2), MotionType::Kinematic),
                Activation::Activate)
            .Value();

    constexpr int cThreads = 2, cPerThread = 4;
    CharacterSettings settings;
    settings.mShape = CapsuleShape::Create(cHalfHeight, cRadius).Value();
    std::vector<CharacterController> characters;
    for (int i = 0; i < cThreads * cPerThread; ++i)
    {
        // The last of each thread's characters stands on the elevator and walks a small circle there
        const bool onElevator = i % cPerThread == cPerThread - 1;
        const Vec3 centre = onElevator ? Vec3(8.0f + float(i / cPerThread) * 0.4f - 0.2f, 0, 8)
                                       : Vec3(-12.0f + 6.0f * float(i % 5), 0, -8.0f + 8.0f * float(i / 5));
        const float floorTop = onElevator ? cElevatorLow + 0.25f : 0.0f;
        characters.push_back(
            CharacterController::Create(*world, settings,
                                        centre + Vec3(0, floorTop + cHalfHeight + cRadius + 0.02f, 0))
                .Value());
    }

    const Clock::duration minTime = std::chrono::milliseconds(1000);
    const Clock::duration maxTime = std::chrono::milliseconds(test::cSlowBuild ? 8000 : 20000);
    const uint64_t targetSteps = test::cSlowBuild ? 60 : 300;
    std::atomic<bool> stop{false};
    // A game's pace: a walker's frame f runs once the world has made step f - 1, beside step f, and step f
    // waits for every walker's frame f - 1 (a character that missed a hundred steps would find its elevator
    // metres away). Relaxed throughout: a pace only; what a character reads of the world is ordered by the
    // world's own publication
    std::atomic<uint64_t> steps{0};
    std::array<std::atomic<uint64_t>, cThreads> walkerFrames{};
    std::mutex failureMutex; // Guards firstFailure and failures: written by the character threads
    std::string firstFailure;
    uint64_t failures = 0;
    auto fail = [&](const std::string& inWhat)
    {
        const std::lock_guard lock(failureMutex);
        if (failures++ == 0) firstFailure = inWhat;
    };

    std::vector<std::thread> walkers;
    for (int t = 0; t < cThreads; ++t)
        walkers.emplace_back(
            [&, t]
            {
                float time = 0.0f;
                // Relaxed: a stop flag only
                for (uint64_t frame = 0; !stop.load(std::memory_order_relaxed); ++frame)
                {
                    while (steps.load(std::memory_order_relaxed) + 1 < frame &&
                           !stop.load(std::memory_order_relaxed))
                        std::this_thread::yield();
                    time += cDeltaTime;
                    for (int i = t * cPerThread; i < (t + 1) * cPerThread; ++i)
                    {
                        CharacterController& character = characters[size_t(i)];
                        const bool onElevator = i % cPerThread == cPerThread - 1;
                        const float radius = onElevator ? 0.6f : 3.0f, speed = onElevator ? 0.8f : 3.0f;
                        const float angle = time * speed / radius + float(i);
                        Vec3 velocity(-std::sin(angle) * speed, character.GetLinearVelocity().y(),
                                      std::cos(angle) * speed);
                        const Status set = character.SetLinearVelocity(velocity);
                        const Status updated = character.Update(cDeltaTime, cGravity);
                        if (!set || !updated)
                        {
                            fail("character " + std::to_string(i) + ": " +
                                 (set ? updated : set).GetError().mMessage);
                            continue;
                        }
                        // Its foot stays out of the floor, and a rider's out of the elevator's top as last
                        // published, but for a step's rise (2.6 cm at most) that the rider has still to
                        // follow
                        float floorTop = 0.0f;
                        if (onElevator)
                        {
                            PoseReader poses(world->GetBodyManager());
                            PublishedPose pose;
                            floorTop =
                                poses.Read(elevator, pose) ? pose.mTransform.mPosition.y() + 0.25f : 0.0f;
                        }
                        const float foot = character.GetPosition().y() - cHalfHeight - cRadius;
                        if (foot < floorTop - cSinkTolerance)
                            fail("character " + std::to_string(i) + "'s foot sank to " +
                                 std::to_string(foot) + " m, its floor's top at " + std::to_string(floorTop));
                    }
                    walkerFrames[size_t(t)].store(frame + 1, std::memory_order_relaxed);
                }
            });

    // This thread steps the world on a job system, moves the elevator and adds and removes crates
    jobs::JobSystem::Settings jobSettings;
    jobSettings.mNumThreads = 2;
    jobs::JobSystem jobSystem(jobSettings);
    std::mt19937 random(11);
    // Crates fall beside the walkers (whose circles reach x = 18), so that bodies come and go in the broad
    // phase the characters query without landing on them
    std::uniform_real_distribution<float> crateX(20.0f, 28.0f), crateZ(-20.0f, 20.0f);
    std::deque<BodyID> crates;
    const Clock::time_point start = Clock::now();
    for (uint64_t step = 0;; ++step)
    {
        const Clock::duration elapsed = Clock::now() - start;
        if ((elapsed >= minTime && step >= targetSteps) || elapsed >= maxTime) break;
        const auto walkersBehind = [&]
        {
            for (const std::atomic<uint64_t>& frames : walkerFrames)
                if (frames.load(std::memory_order_relaxed) < step) return true;
            return false;
        };
        while (walkersBehind() && Clock::now() - start < maxTime)
            std::this_thread::yield();
        {
            const std::lock_guard lock(failureMutex);
            if (failures > 0) break;
        }
        const float phase = float(step % 240) / 240.0f; // Up and down every 4 s
        const float height = cElevatorLow + cElevatorRise * (1.0f - std::cos(2.0f * cPi * phase)) * 0.5f;
        // (a failure here ends the loop, not the test: the walkers are still to be stopped and joined)
        if (!bodies.MoveKinematic(elevator, Vec3(8, height, 8), Quat::Identity(), cDeltaTime))
        {
            fail("MoveKinematic refused");
            break;
        }
        Result<BodyID> crate =
            bodies.CreateAndAddBody(test::BoxBodySettings(Vec3(crateX(random), 6, crateZ(random)),
                                                          Vec3::Constant(0.2f), MotionType::Dynamic),
                                    Activation::Activate);
        if (!crate)
        {
            fail("a crate was refused: " + crate.GetError().mMessage);
            break;
        }
        crates.push_back(crate.Value());
        if (crates.size() > 40)
        {
            if (!bodies.RemoveBody(crates.front()) || !bodies.DestroyBody(crates.front()))
            {
                fail("a crate's removal was refused");
                break;
            }
            crates.pop_front();
        }
        if (const Status updated = world->Update(cDeltaTime, 1, jobSystem); !updated)
        {
            fail("Update: " + updated.GetError().mMessage);
            break;
        }
        steps.store(step + 1, std::memory_order_relaxed);
    }
    stop.store(true, std::memory_order_relaxed); // Relaxed: a stop flag; the joins order the rest
    for (std::thread& walker : walkers)
        walker.join();

    EXPECT_EQ(failures, 0u) << failures << " failures, the first: " << firstFailure;
    EXPECT_GE(steps.load(std::memory_order_relaxed), test::cSlowBuild ? 10u : targetSteps);
    // The elevator's riders went up and down with it: each is still on it, within its 4 m square
    for (int i = cPerThread - 1; i < cThreads * cPerThread; i += cPerThread)
    {
        const Vec3 position = characters[size_t(i)].GetPosition();
        EXPECT_LT((Vec3(position.x(), 0, position.z()) - Vec3(8, 0, 8)).cwiseAbs().maxCoeff(), 2.0f)
            << "character " << i;
        EXPECT_GE(position.y(), bodies.GetPosition(elevator).Value().y() + 0.25f + cHalfHeight) << i;
    }
}

TEST(CharacterConcurrencyTest, GroupMembersOnTwoThreadsMeetWithoutPassingThroughEachOther)
{
    const std::unique_ptr<PhysicsSystem> world = test::MakePhysicsSystem();
    ASSERT_TRUE(world->GetBodyInterface().CreateAndAddBody(test::StaticFloorSettings(30.0f),
                                                           Activation::DontActivate));
    // Eight members on a ring, each walking through the centre to its opposite place: they all meet there
    constexpr int cThreads = 2, cPerThread = 4, cMembers = cThreads * cPerThread;
    constexpr float cRing = 3.0f, cSpeed = 3.0f;
    CharacterSettings settings;
    settings.mShape = CapsuleShape::Create(cHalfHeight, cRadius).Value();
    CharacterGroup group;
    std::vector<CharacterController> members;
    std::vector<Vec3> goals;
    for (int i = 0; i < cMembers; ++i)
    {
        const float angle = 2.0f * cPi * float(i) / float(cMembers);
        const Vec3 place(cRing * std::cos(angle), cHalfHeight + cRadius + 0.02f, cRing * std::sin(angle));
        members.push_back(CharacterController::Create(*world, settings, place).Value());
        goals.push_back(Vec3(-place.x(), place.y(), -place.z()));
    }
    for (CharacterController& member : members)
        ASSERT_TRUE(group.Add(member));

    // A frame: the members update on their threads while this one steps the world; then, with every Update
    // done (the barrier orders them), the group publishes: its sync point
    std::barrier frameEdge(cThreads + 1);
    std::atomic<bool> stop{false}; // Relaxed: read after the barrier, which orders it
    std::mutex failureMutex;       // Guards firstFailure: written by the member threads
    std::string firstFailure;
    std::vector<std::thread> threads;
    for (int t = 0; t < cThreads; ++t)
        threads.emplace_back(
            [&, t]
            {
                for (;;)
                {
                    frameEdge.arrive_and_wait(); // The frame starts
                    if (stop.load(std::memory_order_relaxed)) return;
                    for (int i = t * cPerThread; i < (t + 1) * cPerThread; ++i)
                    {
                        CharacterController& member = members[size_t(i)];
                        Vec3 toGoal = goals[size_t(i)] - member.GetPosition();
                        toGoal.y() = 0.0f;
                        Vec3 velocity =
                            toGoal.norm() > 0.1f ? Vec3(toGoal.normalized() * cSpeed) : Vec3::Zero();
                        velocity.y() = member.GetLinearVelocity().y();
                        const Status set = member.SetLinearVelocity(velocity);
                        const Status updated = member.Update(cDeltaTime, cGravity);
                        if (!set || !updated)
                        {
                            const std::lock_guard lock(failureMutex);
                            if (firstFailure.empty())
                                firstFailure = "member " + std::to_string(i) + ": " +
                                               (set ? updated : set).GetError().mMessage;
                        }
                    }
                    frameEdge.arrive_and_wait(); // Its Updates are done
                }
            });

    jobs::JobSystem::Settings jobSettings;
    jobSettings.mNumThreads = 2;
    jobs::JobSystem jobSystem(jobSettings);
    const int frames = test::cSlowBuild ? 120 : 240;
    float deepest = 0.0f;
    int contacts = 0;
    for (int frame = 0; frame < frames; ++frame)
    {
        frameEdge.arrive_and_wait();
        const Status stepped = world->Update(cDeltaTime, 1, jobSystem);
        frameEdge.arrive_and_wait();
        EXPECT_TRUE(stepped.IsOk());
        group.Publish();
        for (int i = 0; i < cMembers; ++i)
        {
            contacts += int(members[size_t(i)].GetCharacterContacts().size());
            for (int j = i + 1; j < cMembers; ++j)
            {
                const Vec3 between = members[size_t(i)].GetPosition() - members[size_t(j)].GetPosition();
                deepest = std::min(deepest, Vec3(between.x(), 0, between.z()).norm() - 2.0f * cRadius);
            }
        }
    }
    stop.store(true, std::memory_order_relaxed);
    frameEdge.arrive_and_wait(); // Lets the threads see the stop
    for (std::thread& thread : threads)
        thread.join();

    EXPECT_TRUE(firstFailure.empty()) << firstFailure;
    EXPECT_GT(contacts, 0) << "they met";
    // Each sees the others a frame late, so a crowd pressing together overlaps by a few frames' walk at most,
    // and is pushed apart in the next Updates
    EXPECT_GT(deepest, -4.0f * cSpeed * cDeltaTime);
    for (const CharacterController& member : members)
        EXPECT_GE(member.GetPosition().y(), cHalfHeight + cRadius - cSinkTolerance) << "on the floor";
}

} // namespace
} // namespace cairn
