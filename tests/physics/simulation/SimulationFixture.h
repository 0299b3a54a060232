#pragma once

// A small world and helpers to build test scenes: every simulation test starts from here.
// The world steps on this thread, or on a job system of CAIRN_TEST_PHYSICS_THREADS threads when that is set
// (ctest runs the simulation tests once more with 1, 2 and 4 threads, a sanitizer build with 2 only:
// tests/CMakeLists.txt).

#include "cairn/jobs/JobSystem.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "common/MakePhysicsSystem.h"

#include <cstdlib>
#include <gtest/gtest.h>
#include <memory>

namespace cairn::test
{
using namespace cairn::physics;

class SimulationFixture : public ::testing::Test
{
protected:
    static constexpr float cDeltaTime = 1.0f / 60.0f;

    /// Recreates the world with non-default settings.
    void ResetWorld(const PhysicsSettings& inSettings) { mSystem = MakePhysicsSystem(inSettings); }

    PhysicsSystem& System() { return *mSystem; }
    BodyInterface& Bodies() { return mSystem->GetBodyInterface(); }

    static ShapeRef Box(const Vec3& inHalfExtent) { return BoxShape::Create(inHalfExtent).Value(); }
    static ShapeRef Sphere(float inRadius) { return SphereShape::Create(inRadius).Value(); }

    BodyID AddStatic(const ShapeRef& inShape, const Vec3& inPosition,
                     const Quat& inRotation = Quat::Identity(), float inFriction = 0.5f,
                     float inRestitution = 0.0f)
    {
        BodyCreationSettings settings;
        settings.mShape = inShape;
        settings.mPosition = inPosition;
        settings.mRotation = inRotation;
        settings.mMotionType = MotionType::Static;
        settings.mObjectLayer = Layers::cStatic;
        settings.mFriction = inFriction;
        settings.mRestitution = inRestitution;
        return Bodies().CreateAndAddBody(settings, Activation::DontActivate).Value();
    }

    /// The default floor: a static box whose top face is y = 0.
    BodyID AddFloor(float inFriction = 0.5f)
    {
        return AddStatic(Box(Vec3(50, 1, 50)), Vec3(0, -1, 0), Quat::Identity(), inFriction);
    }

    static BodyCreationSettings DynamicSettings(const ShapeRef& inShape, const Vec3& inPosition)
    {
        BodyCreationSettings settings;
        settings.mShape = inShape;
        settings.mPosition = inPosition;
        settings.mMotionType = MotionType::Dynamic;
        settings.mObjectLayer = Layers::cMoving;
        return settings;
    }

    BodyID AddDynamic(const BodyCreationSettings& inSettings)
    {
        return Bodies().CreateAndAddBody(inSettings, Activation::Activate).Value();
    }

    /// The job system the tests step on, or null (CAIRN_TEST_PHYSICS_THREADS unset or not a number > 0).
    static jobs::JobSystem* TestJobSystem()
    {
        static const std::unique_ptr<jobs::JobSystem> jobSystem = []() -> std::unique_ptr<jobs::JobSystem>
        {
            const char* value = std::getenv("CAIRN_TEST_PHYSICS_THREADS");
            const int threads = value != nullptr ? std::atoi(value) : 0;
            if (threads <= 0) return nullptr;
            jobs::JobSystem::Settings settings;
            settings.mNumThreads = uint32_t(threads);
            return std::make_unique<jobs::JobSystem>(settings);
        }();
        return jobSystem.get();
    }

    static Status UpdateWorld(PhysicsSystem& ioSystem, float inDeltaTime, int inCollisionSteps = 1)
    {
        jobs::JobSystem* jobSystem = TestJobSystem();
        return jobSystem != nullptr ? ioSystem.Update(inDeltaTime, inCollisionSteps, *jobSystem)
                                    : ioSystem.Update(inDeltaTime, inCollisionSteps);
    }
    Status UpdateWorld(float inDeltaTime, int inCollisionSteps = 1)
    {
        return UpdateWorld(System(), inDeltaTime, inCollisionSteps);
    }

    void Step(int inSteps)
    {
        for (int i = 0; i < inSteps; ++i)
            ASSERT_TRUE(UpdateWorld(cDeltaTime).IsOk());
    }

    Vec3 Position(const BodyID& inID) { return Bodies().GetPosition(inID).Value(); }
    Vec3 Velocity(const BodyID& inID) { return Bodies().GetLinearVelocity(inID).Value(); }
    bool IsActive(const BodyID& inID) { return Bodies().IsActive(inID).Value(); }

    std::unique_ptr<PhysicsSystem> mSystem = MakePhysicsSystem();
};

} // namespace cairn::test
