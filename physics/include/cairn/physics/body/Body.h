#pragma once

// Body: one rigid body. Bodies live in the BodyManager's fixed array and are read and written only under
// their body mutex (BodyLockRead / BodyLockWrite), or by the physics step, which holds every body mutex for
// write while it runs. Nothing in a Body is atomic: the lock is the synchronisation.

#include "cairn/physics/body/BodyCreationSettings.h"
#include "cairn/physics/body/BodyID.h"

#include <atomic>
#include <cassert>

namespace cairn::physics
{

class Body
{
public:
    static constexpr uint32_t cInactive = 0xffffffffu;

    BodyID GetID() const { return mID; }
    MotionType GetMotionType() const { return mMotionType; }
    bool IsStatic() const { return mMotionType == MotionType::Static; }
    bool IsDynamic() const { return mMotionType == MotionType::Dynamic; }
    bool IsKinematic() const { return mMotionType == MotionType::Kinematic; }
    ObjectLayer GetObjectLayer() const { return mObjectLayer; }
    /// Its collision group and part (CollisionGroup.h; the group's table: BodyManager::BodiesCollide)
    uint32_t GetCollisionGroupID() const { return mCollisionGroupID; }
    uint32_t GetCollisionSubGroupID() const { return mCollisionSubGroupID; }
    bool IsInWorld() const { return mInWorld; }
    bool IsActive() const { return GetActiveIndex() != cInactive; }

    const ShapeRef& GetShape() const { return mShape; }
    /// Centre of mass in world space.
    const Vec3& GetCenterOfMassPosition() const { return mPosition; }
    /// World position of the shape's origin.
    Vec3 GetPosition() const { return mPosition - mRotation * mCenterOfMassOffset; }
    const Quat& GetRotation() const { return mRotation; }
    /// Transform of the shape (shape-local to world).
    Transform GetTransform() const { return {GetPosition(), mRotation}; }
    const AABB& GetWorldBounds() const { return mBounds; }

    const Vec3& GetLinearVelocity() const { return mLinearVelocity; }
    const Vec3& GetAngularVelocity() const { return mAngularVelocity; }
    /// Velocity of a world-space point attached to the body.
    Vec3 GetPointVelocity(const Vec3& inWorldPoint) const
    {
        return mLinearVelocity + mAngularVelocity.cross(inWorldPoint - mPosition);
    }

    float GetInverseMass() const { return mInvMass; }
    /// Inverse inertia tensor in world space (zero for static and kinematic bodies).
    Mat3 GetInverseInertiaWorld() const
    {
        const Mat3 r = (mRotation * mInertiaRotation).toRotationMatrix();
        return r * mInvInertiaDiagonal.asDiagonal() * r.transpose();
    }

    float GetFriction() const { return mFriction; }
    float GetRestitution() const { return mRestitution; }
    uint8_t GetNavMeshArea() const { return mNavMeshArea; }
    uint64_t GetUserData() const { return mUserData; }
    bool GetAllowSleeping() const { return mAllowSleeping; }
    /// Whether inShape can carry a dynamic body of density inDensity (a volume, a mass in range):
    /// CreateBody's checks, which a change of shape or motion type repeats.
    static Status CheckDynamicMass(const Shape& inShape, float inDensity);
    bool IsSensor() const { return mIsSensor; }
    MotionQuality GetMotionQuality() const { return mMotionQuality; }

private:
    friend class BodyManager;
    friend class BodyInterface;
    friend class PhysicsSystem;
    friend class PublishedPoseStore;
    // The step's stages, which move and wake bodies while the step holds every body mutex
    friend class Integration;
    friend class ContactsStage;
    friend class IslandSolver;
    friend class FinishStage;
    friend class IslandSleep;
    friend class JointStage;

    /// Sets mass properties and everything else from the settings (validated by the caller).
    void Init(const BodyID& inID, const BodyCreationSettings& inSettings);
    /// Sets the centre of mass offset for the shape and motion type (the shape's centre of mass; zero for a
    /// static body) and, with inRecomputeMass, the mass and inertia (the shape's at mDensity for a dynamic
    /// body, none for the others). mPosition is left alone: the caller puts it where the shape's origin
    /// stays.
    void SetMassProperties(bool inRecomputeMass);
    void UpdateBounds() { mBounds = mShape->GetWorldBounds(GetTransform()); }
    // Relaxed: the index is only changed under the active-list mutex (or by the step, which holds
    // everything); a reader under the body lock needs only active vs inactive, which no concurrent swap of
    // another body changes
    uint32_t GetActiveIndex() const { return mActiveIndex.load(std::memory_order_relaxed); }
    void SetActiveIndex(uint32_t inIndex) { mActiveIndex.store(inIndex, std::memory_order_relaxed); }

    // Hot data first: what the solver and integrator touch every step
    Vec3 mPosition;           ///< Centre of mass, world
    Quat mRotation;           ///< World rotation
    Vec3 mLinearVelocity;     ///< m/s
    Vec3 mAngularVelocity;    ///< rad/s, world
    Vec3 mForce;              ///< Accumulated until the next Update, acting over all its collision steps, N
    Vec3 mTorque;             ///< As mForce, N m
    Quat mInertiaRotation;    ///< Rotates the principal axes of inertia into body space
    Vec3 mInvInertiaDiagonal; ///< Inverse principal moments (0 for static/kinematic)
    float mInvMass;           ///< 0 for static/kinematic
    Vec3 mCenterOfMassOffset; ///< Centre of mass in shape-local space
    AABB mBounds;             ///< World bounds as last pushed to the broad phase
    ShapeRef mShape;          ///< Immutable, shared
    float mFriction;
    float mRestitution;
    float mLinearDamping;
    float mAngularDamping;
    float mGravityFactor;
    float mDensity; ///< kg/m^3: the mass of a body made dynamic later or given a new shape
    float mMaxLinearVelocity;
    float mMaxAngularVelocity;
    float mSleepTimer = 0.0f; ///< Seconds this body has been slow enough to sleep
    std::atomic<uint32_t> mActiveIndex =
        cInactive; ///< Index in the active list, or cInactive; see GetActiveIndex
    BodyID mID;
    uint64_t mUserData;
    /// Next body of the island this body fell asleep with: a ring. An id, not an index: a member removed and
    /// destroyed since leaves a stale link, and its slot may hold another body by now
    BodyID mSleepRingNext;
    uint32_t mCollisionGroupID;    ///< CollisionGroup::cNoGroup: none
    uint16_t mCollisionSubGroupID; ///< Below GroupFilterTable::cMaxSubGroups
    MotionType mMotionType;
    ObjectLayer mObjectLayer;
    uint8_t mNavMeshArea;
    bool mAllowSleeping;
    bool mIsSensor;
    MotionQuality mMotionQuality;
    /// Counts SetShape calls (wrapping): the narrow phase's body-pair cache takes manifolds over only from
    /// the same shapes
    uint16_t mShapeGeneration;
    bool mInWorld = false;    ///< Added to the broad phase and simulated
    bool mAddPending = false; ///< In a prepared add batch that is not finalized yet
    bool mWakeIsland = false; ///< Woken from outside the step: the step wakes its sleeping island too
};

} // namespace cairn::physics
