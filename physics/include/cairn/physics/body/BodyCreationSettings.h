#pragma once

// Everything needed to create a body. Plain value type.

#include "cairn/physics/body/CollisionGroup.h"
#include "cairn/physics/body/Layers.h"
#include "cairn/physics/body/MotionType.h"
#include "cairn/physics/shapes/Shape.h"

namespace cairn::physics
{

/// The heaviest dynamic body CreateBody takes, kg (a rock cube of about 700 m). Contact impulses are mass
/// times speed and friction squares them, so a heavier body could overflow a float on landing.
constexpr float cMaxBodyMass = 1.0e12f;

struct BodyCreationSettings
{
    ShapeRef mShape;                      ///< Required
    Vec3 mPosition = Vec3::Zero();        ///< World position of the shape's origin
    Quat mRotation = Quat::Identity();    ///< World rotation (unit)
    Vec3 mLinearVelocity = Vec3::Zero();  ///< Of the centre of mass, m/s
    Vec3 mAngularVelocity = Vec3::Zero(); ///< rad/s, world space
    MotionType mMotionType = MotionType::Dynamic;
    ObjectLayer mObjectLayer = Layers::cMoving;
    CollisionGroup mCollisionGroup;    ///< Within one object (a ragdoll): which of its parts collide
    float mDensity = 1000.0f;          ///< kg/m^3, used for the mass of dynamic bodies (at most cMaxBodyMass)
    float mFriction = 0.2f;            ///< Coulomb coefficient, >= 0 (combined as sqrt(a * b))
    float mRestitution = 0.0f;         ///< In [0, 1] (combined as max(a, b))
    float mLinearDamping = 0.05f;      ///< 1/s: dv/dt = -c v
    float mAngularDamping = 0.05f;     ///< 1/s
    float mGravityFactor = 1.0f;       ///< Scales the world's gravity for this body
    float mMaxLinearVelocity = 500.0f; ///< m/s, clamped each step
    float mMaxAngularVelocity = 0.25f * 3.14159265f * 60.0f; ///< rad/s: a quarter turn per 1/60 s step
    bool mAllowSleeping = true;
    /// A sensor makes no contacts that push: it reports the dynamic bodies that enter and leave it
    /// (ContactListener.h)
    bool mIsSensor = false;
    MotionQuality mMotionQuality = MotionQuality::Discrete; ///< Dynamic bodies: see MotionQuality
    uint8_t mNavMeshArea = 0; ///< Navmesh area type (0 = default walkable); the navmesh reads it
    uint64_t mUserData = 0;   ///< Free for the game
};

} // namespace cairn::physics
