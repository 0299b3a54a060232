// Joints added, toggled and removed from other threads while the step runs on a job system (issue 33): no
// data race (this suite runs under ThreadSanitizer), no deadlock between the joints' mutex and the body
// mutexes, every call answered, and the jointed bodies' poses stay finite.

#include "cairn/jobs/JobSystem.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "common/MakePhysicsSystem.h"
#include "common/StaticFloor.h"

#include <atomic>
#include <gtest/gtest.h>
#include <thread>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

TEST(ConstraintInterfaceConcurrencyTest, JointsComeAndGoWhileTheWorldSteps)
{
    jobs::JobSystem jobSystem(jobs::JobSystem::Settings{2});
    const std::unique_ptr<PhysicsSystem> system = test::MakePhysicsSystem();
    BodyInterface& bodies = system->GetBodyInterface();
    ASSERT_TRUE(bodies.CreateAndAddBody(test::StaticFloorSettings(50.0f), Activation::DontActivate).IsOk());
    // Each thread its own pair of spheres, joined and let go over and over
    constexpr int cThreads = 3;
    std::vector<std::pair<BodyID, BodyID>> pairs;
    for (int t = 0; t < cThreads; ++t)
    {
        BodyCreationSettings sphere;
        sphere.mShape = SphereShape::Create(0.25f).Value();
        sphere.mMotionType = MotionType::Dynamic;
        sphere.mObjectLayer = Layers::cMoving;
        sphere.mPosition = Vec3(3.0f * float(t), 2.0f, 0.0f);
        const BodyID a = bodies.CreateAndAddBody(sphere, Activation::Activate).Value();
        sphere.mPosition += Vec3(0.0f, 0.0f, 1.0f);
        const BodyID b = bodies.CreateAndAddBody(sphere, Activation::Activate).Value();
        pairs.push_back({a, b});
    }
    std::atomic<bool> stop{false};
    std::atomic<int> failures{0}, calls{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < cThreads; ++t)
        threads.emplace_back(
            [&, t]
            {
                ConstraintInterface& joints = system->GetConstraintInterface();
                for (int round = 0; !stop.load(std::memory_order_relaxed) || round < 20; ++round)
                {
                    PointConstraintSettings settings;
                    settings.mBodyA = pairs[size_t(t)].first;
                    settings.mBodyB = round % 3 == 0 ? BodyID() : pairs[size_t(t)].second; // Or the world
                    settings.mPoint = Vec3(3.0f * float(t), 2.0f, 0.5f);
                    Result<ConstraintID> id = joints.AddPoint(settings);
                    if (!id)
                        ++failures;
                    else
                    {
                        failures += joints.SetEnabled(id.Value(), round % 2 == 0).IsOk() ? 0 : 1;
                        failures += joints.IsEnabled(id.Value()).IsOk() ? 0 : 1;
                        std::this_thread::yield();
                        failures += joints.Remove(id.Value()).IsOk() ? 0 : 1;
                    }
                    calls.fetch_add(1, std::memory_order_relaxed);
                }
            });
    for (int step = 0; step < 120; ++step)
        ASSERT_TRUE(system->Update(1.0f / 60.0f, 1, jobSystem).IsOk());
    stop = true;
    for (std::thread& thread : threads)
        thread.join();
    EXPECT_EQ(failures.load(), 0);
    EXPECT_GE(calls.load(), cThreads * 20);
    EXPECT_EQ(system->GetConstraintInterface().GetNumConstraints().Value(), 0u);
    for (const auto& [a, b] : pairs)
    {
        EXPECT_TRUE(bodies.GetPosition(a).Value().allFinite());
        EXPECT_TRUE(bodies.GetPosition(b).Value().allFinite());
    }
}

} // namespace
} // namespace cairn
