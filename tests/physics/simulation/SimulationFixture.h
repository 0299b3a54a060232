#pragma once

// A small world and helpers to build test scenes: every simulation test starts from here.

#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"

#include <gtest/gtest.h>

namespace cairn::test
{

class SimulationFixture : public ::testing::Test
{
protected:
    static constexpr float cDeltaTime = 1.0f / 60.0f;

    /// Recreates the world with non-default settings.
    void ResetWorld(const PhysicsSettings& inSettings)
    {
        mSystem = std::make_unique<PhysicsSystem>(inSettings);
    }

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

    void Step(int inSteps)
    {
        for (int i = 0; i < inSteps; ++i)
            ASSERT_TRUE(System().Update(cDeltaTime).IsOk());
    }

    Vec3 Position(const BodyID& inID) { return Bodies().GetPosition(inID).Value(); }
    Vec3 Velocity(const BodyID& inID) { return Bodies().GetLinearVelocity(inID).Value(); }
    bool IsActive(const BodyID& inID) { return Bodies().IsActive(inID).Value(); }

    std::unique_ptr<PhysicsSystem> mSystem = std::make_unique<PhysicsSystem>();
};

} // namespace cairn::test
