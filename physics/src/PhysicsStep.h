#pragma once

// PhysicsStep: the work of one collision step, and the scratch memory it reuses from step to step (so a warm
// scene allocates nothing). Owned by PhysicsSystem; runs on the thread that called Update, which holds every
// body mutex for the whole step: nothing here takes a lock except the broad phase's own.

#include "cairn/physics/PhysicsSettings.h"
#include "cairn/physics/body/BodyManager.h"
#include "cairn/physics/broadphase/BroadPhase.h"
#include "cairn/physics/islands/IslandBuilder.h"
#include "cairn/physics/solver/ContactCache.h"
#include "cairn/physics/solver/ContactConstraint.h"

#include <vector>

namespace cairn
{

class PhysicsStep
{
public:
    PhysicsStep(const PhysicsSettings& inSettings, const LayerSetup& inLayers, BodyManager& ioBodies,
                BroadPhase& ioBroadPhase);

    /// One collision step of inDeltaTime seconds; adds its figures to ioStatistics.
    void Run(float inDeltaTime, StepStatistics& ioStatistics);

private:
    struct BodyPair
    {
        uint32_t mA; ///< Body indices, mA < mB
        uint32_t mB;
    };

    /// Wakes the sleeping islands of bodies that were woken from outside the step since the last one.
    void WakeIslandsOfWokenBodies();
    void ApplyForces(std::span<const uint32_t> inBodies, float inDeltaTime);
    /// Finds pairs for active-list entries [inBegin, end) and collides them; may activate more bodies.
    void CollideNewlyActive(size_t inBegin, float inDeltaTime);
    void CollidePair(Body& ioA, Body& ioB, float inDeltaTime);
    void AddConstraint(Body& ioA, Body& ioB, const ContactManifold& inManifold, float inDeltaTime);
    void BuildIslands();
    void SolveIsland(uint32_t inIsland, float inDeltaTime);
    void IntegratePositions(Body& ioBody, float inDeltaTime);
    void UpdateBoundsAndSleep(float inDeltaTime);

    const PhysicsSettings& mSettings;
    const LayerSetup& mLayers;
    BodyManager& mBodies;
    BroadPhase& mBroadPhase;

    ContactCache mContactCache;
    IslandBuilder mIslands;
    std::vector<BodyPair> mPairs;                       ///< Scratch: pairs of the slice being collided
    std::vector<ContactConstraint> mConstraints;        ///< This step's contacts
    std::vector<uint32_t> mConstraintStart;             ///< Per island offsets into mIslandConstraints
    std::vector<ContactConstraint*> mIslandConstraints; ///< Constraints grouped by island
    std::vector<BroadPhaseBody> mMovedBodies;           ///< Scratch for the broad-phase notify
    std::vector<uint32_t> mSleepingIslands;             ///< Scratch
    uint32_t mNumBodyPairs = 0;                         ///< Counters of the running step
    uint32_t mNumWarmStartedPoints = 0;
};

} // namespace cairn
