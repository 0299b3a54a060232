#pragma once

// The published poses' "no miss" stress (PublishedPose.h), shared by the short run in the concurrency suite
// (under ThreadSanitizer in CI) and the long run (2 million checks, label "long").
//
// The world: a static floor in a closed static box (walls and a roof, so nothing leaves); a pile of dynamic
// boxes and spheres (sleeping off, so they never stop being stepped) that four kinematic pistons, one per
// side, squeeze together and let go again and again while two kinematic paddles spin in its middle, all
// driven by velocity (SetLinearVelocity / SetAngularVelocity), so the pile is pushed by contacts all the
// time; and a few dynamic boxes that a thread moves by hand. Threads:
//  - the step thread runs Update back to back (alone, or on a job system), and between two updates turns the
//    pistons round at the ends of their stroke, turns the paddles round now and then, and every 16th update
//    rebuilds the whole broad phase (BroadPhaseQuadTree::RebuildAll);
//  - a mover thread moves its boxes by hand (SetPositionAndRotation, which publishes);
//  - a churn thread creates batches of 16 bodies (dynamic spheres dropped over the pile, static plates above
//    it), adds them (AddBodiesPrepare / AddBodiesFinalize), lets the world step, removes and destroys them;
//  - query threads each pick a random moving body (dynamic or kinematic), read its published pose (version
//    v1), pick a point well inside its shape at that pose, run CollidePoint there, CollideAABox on a 2 cm
//    box around it and CastShapeAll of a 1 cm sphere swept to it from outside the shape (from a random
//    side), and read the pose again (v2).
// With v1 == v2 nothing was published for that body between the two reads, so during the queries the world
// published exactly the pose the point was chosen in: all three queries must report the body. Each such query
// is a "check", and a check that does not report the body is a "miss". With v1 != v2 a query may rightly
// have seen another pose: it is counted as inconclusive, never as a check.
// Every id any query reports (also those of a box query among the churned bodies, made to see many of them)
// must be a body in the world during the query: a body the test never created, a churned body never added, or
// one whose RemoveBody had returned before the query started is a "stale id". The same id twice in one
// result is a "duplicate", and a published rotation that is not unit length (a pose torn between two
// publications would mix two rotations' components) is a "torn pose".

#include "broadphase/BroadPhaseQuadTree.h"
#include "cairn/jobs/JobSystem.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/body/PublishedPose.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "common/MakePhysicsSystem.h"
#include "common/SlowBuild.h"
#include "common/StaticFloor.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <gtest/gtest.h>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;

struct PublishedPoseStressConfig
{
    uint32_t mNumBoxes = 130;   ///< Dynamic boxes in the pile
    uint32_t mNumSpheres = 70;  ///< Dynamic spheres in the pile
    uint32_t mNumHandMoved = 8; ///< Dynamic boxes the mover thread moves by hand
    uint32_t mChurnBatch = 16;  ///< Bodies the churn thread adds and removes at a time
    uint32_t mNumQueryThreads = 2;
    uint32_t mJobThreads = 0;       ///< The step's job system (the calling thread included); 0: no job system
    uint64_t mTargetChecks = 50000; ///< Stop once this many checks are done...
    /// ...and this many updates (enough for every piston to turn round and the paddles to turn once)...
    uint64_t mMinUpdates = 320;
    std::chrono::milliseconds mMinDuration{1000};  ///< ...and at least this long has passed,
    std::chrono::milliseconds mMaxDuration{20000}; ///< or when this has passed
};

struct PublishedPoseStressResult
{
    uint64_t mChecks = 0;               ///< Conclusive queries (v1 == v2)
    uint64_t mChecksDuringStep = 0;     ///< Of those, made while Update was running (at the start or the end)
    uint64_t mMisses = 0;               ///< Checks that did not report their body
    uint64_t mInconclusive = 0;         ///< Queries whose body was published again meanwhile (v1 != v2)
    uint64_t mInconclusiveNotFound = 0; ///< Of those, queries that did not report it (it had moved away)
    uint64_t mStaleIDs = 0;             ///< Reported ids of bodies not in the world during the query
    uint64_t mDuplicates = 0;           ///< An id reported twice by one query
    uint64_t mTornPoses = 0;            ///< Published rotations that are not unit length
    uint64_t mUnreadableTargets = 0;    ///< A permanent body whose pose could not be read
    uint64_t mProbes = 0;               ///< Box queries among the churned bodies
    uint64_t mChurnedReported = 0;      ///< Churned bodies' ids reported by any query
    /// Of those, bodies that had left the world when checked (removed while the query ran)
    uint64_t mRemovedDuringQuery = 0;
    uint64_t mUpdates = 0;
    uint64_t mFullRebuilds = 0;
    uint64_t mKinematicChanges = 0; ///< Velocities set on the pistons and paddles
    uint64_t mHandMoves = 0;
    uint64_t mChurnBatches = 0;
    uint64_t mFailedCalls = 0;      ///< A BodyInterface call or a query that returned an error
    uint64_t mRefusedStepCalls = 0; ///< Broad-phase step calls refused for overlapping (must be none)
    uint32_t mBodiesAfter = 0;      ///< Bodies in the body manager once every thread stopped
    uint32_t mPermanentBodies = 0;  ///< Bodies that are never removed
    uint32_t mPileBodies = 0;       ///< Dynamic bodies of the pile
    uint32_t mPileInArena = 0;      ///< Of those, inside the walls once the run stopped
    float mPileMeanSpeed = 0.0f;    ///< Their mean speed then, m/s
    double mSeconds = 0;
    std::vector<std::string> mFailures; ///< The first few failures, described
};

namespace published_pose_stress
{
constexpr float cArenaHalf = 14.0f;  ///< Inner faces of the walls
constexpr float cRoofY = 8.0f;       ///< Underside of the roof
constexpr float cPistonOut = 12.5f;  ///< A piston turns inwards beyond this distance from the middle...
constexpr float cPistonIn = 5.0f;    ///< ...and outwards within this one
constexpr float cPistonSpeed = 1.5f; ///< m/s
constexpr float cPaddleSpin = 1.5f;  ///< rad/s
/// The paddles turn round every this many updates: a second of simulated time, so that even a run cut short
/// by its time cap (ThreadSanitizer on a loaded machine: about 230 updates in 20 s) changes a kinematic
/// velocity mid-run
constexpr uint64_t cPaddleTurnUpdates = 60;
constexpr float cProbeHalfSize = 1.5f;

/// A body a query thread may pick, and how to choose a point well inside it.
struct Target
{
    BodyID mID;
    bool mSphere = false;
    Vec3 mHalfExtent = Vec3::Zero(); ///< Box
    float mRadius = 0.0f;            ///< Sphere
};

inline BodyCreationSettings StaticBox(const Vec3& inCenter, const Vec3& inHalfExtent)
{
    BodyCreationSettings settings;
    settings.mShape = BoxShape::Create(inHalfExtent).Value();
    settings.mPosition = inCenter;
    settings.mMotionType = MotionType::Static;
    settings.mObjectLayer = Layers::cStatic;
    return settings;
}

inline Quat RandomRotation(std::mt19937& ioRandom)
{
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    Quat q(gauss(ioRandom), gauss(ioRandom), gauss(ioRandom), gauss(ioRandom));
    return q.normalized();
}

/// Packs a churned body's state for the stale-id check: created, in the world, or removed at a clock tick.
constexpr uint64_t cCreated = 0;
constexpr uint64_t cInWorld = ~uint64_t(0);
} // namespace published_pose_stress

/// Runs the stress once, on a fresh world. Fills every figure; the caller checks them (ExpectNoMisses...).
inline PublishedPoseStressResult RunPublishedPoseStress(const PublishedPoseStressConfig& inConfig)
{
    using namespace published_pose_stress;
    PublishedPoseStressResult result;

    std::unique_ptr<jobs::JobSystem> jobSystem;
    if (inConfig.mJobThreads > 0)
        jobSystem = std::make_unique<jobs::JobSystem>(jobs::JobSystem::Settings{inConfig.mJobThreads});
    PhysicsSettings settings;
    settings.mMaxBodies = 4096;
    // With a job system, the broad-phase rebuild runs beside the pairs and contacts on any scene, so the
    // queries also meet a rebuild on another thread than the step's
    settings.mUpdateBesideStepMinActiveBodies = 0;
    const std::unique_ptr<PhysicsSystem> system = MakePhysicsSystem(settings);
    BodyInterface& bodies = system->GetBodyInterface();
    // GetBroadPhase() is const, RebuildAll is not; the broad phase itself is not a const object (the system
    // made it), so casting the const away is well defined. It is called from the step thread between two
    // updates, where the step itself runs its rebuilds, so it never overlaps one (mRefusedStepCalls says so)
    auto& quadTree =
        const_cast<BroadPhaseQuadTree&>(dynamic_cast<const BroadPhaseQuadTree&>(system->GetBroadPhase()));

    std::unordered_set<BodyID> permanent; // Read-only once the threads start
    auto addPermanent = [&](const BodyCreationSettings& inSettings, Activation inActivation)
    {
        const BodyID id = bodies.CreateAndAddBody(inSettings, inActivation).Value();
        permanent.insert(id);
        return id;
    };

    // Floor, walls and roof: whatever the pistons do to the pile, it stays in the box
    addPermanent(StaticFloorSettings(cArenaHalf + 2.0f), Activation::DontActivate);
    const float wallHalfHeight = 0.5f * cRoofY + 0.5f;
    for (float side : {-1.0f, 1.0f})
    {
        addPermanent(StaticBox(Vec3(side * (cArenaHalf + 0.5f), wallHalfHeight, 0.0f),
                               Vec3(0.5f, wallHalfHeight, cArenaHalf + 1.0f)),
                     Activation::DontActivate);
        addPermanent(StaticBox(Vec3(0.0f, wallHalfHeight, side * (cArenaHalf + 0.5f)),
                               Vec3(cArenaHalf + 1.0f, wallHalfHeight, 0.5f)),
                     Activation::DontActivate);
    }
    addPermanent(StaticBox(Vec3(0.0f, cRoofY + 0.5f, 0.0f), Vec3(cArenaHalf + 1.0f, 0.5f, cArenaHalf + 1.0f)),
                 Activation::DontActivate);

    std::vector<Target> targets;
    std::mt19937 setupRandom(5);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);

    // Kinematic pistons, one per side (walls 2.5 m high, as long as the box), that squeeze the pile together
    // and let it go, and paddles spinning in its middle. Kinematic bodies do not collide with each other, so
    // the pistons cross at the corners. Their velocities are set through the body interface once they are in
    // the world, as a game would
    struct Piston
    {
        BodyID mID;
        Vec3 mOutwards; ///< Unit: from the middle towards the piston's wall
    };
    std::vector<Piston> pistons;
    std::vector<BodyID> paddles;
    for (const Vec3& outwards : {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 0, 1), Vec3(0, 0, -1)})
    {
        BodyCreationSettings piston;
        const Vec3 halfExtent = outwards.x() != 0.0f ? Vec3(0.25f, 1.25f, cArenaHalf - 0.5f)
                                                     : Vec3(cArenaHalf - 0.5f, 1.25f, 0.25f);
        piston.mShape = BoxShape::Create(halfExtent).Value();
        piston.mPosition = cPistonOut * outwards + Vec3(0.0f, 1.3f, 0.0f);
        piston.mMotionType = MotionType::Kinematic;
        pistons.push_back({addPermanent(piston, Activation::Activate), outwards});
        targets.push_back({pistons.back().mID, false, halfExtent, 0.0f});
        // Inwards first
        if (!bodies.SetLinearVelocity(pistons.back().mID, -cPistonSpeed * outwards)) ++result.mFailedCalls;
    }
    for (float side : {-1.0f, 1.0f})
    {
        BodyCreationSettings paddle;
        paddle.mShape = BoxShape::Create(Vec3(2.0f, 0.3f, 0.25f)).Value();
        paddle.mPosition = Vec3(side * 2.5f, 0.35f, 0.0f);
        paddle.mMotionType = MotionType::Kinematic;
        paddles.push_back(addPermanent(paddle, Activation::Activate));
        targets.push_back({paddles.back(), false, Vec3(2.0f, 0.3f, 0.25f), 0.0f});
        if (!bodies.SetAngularVelocity(paddles.back(), Vec3(0.0f, side * cPaddleSpin, 0.0f)))
            ++result.mFailedCalls;
    }

    // The pile: boxes of various sizes and spheres on a grid above the paddles, tilted so they tumble
    const uint32_t numPile = inConfig.mNumBoxes + inConfig.mNumSpheres;
    const size_t pileBegin = targets.size();
    for (uint32_t i = 0; i < numPile; ++i)
    {
        const uint32_t cell = i % 165, layer = i / 165;
        BodyCreationSettings body;
        body.mPosition = Vec3(-7.0f + float(cell % 15), 1.3f + 1.1f * float(layer), -5.0f + float(cell / 15));
        body.mRotation = RandomRotation(setupRandom);
        body.mAllowSleeping = false; // Stepped, published and pushed for the whole run
        body.mFriction = 0.4f;
        Target target;
        if (i < inConfig.mNumBoxes)
        {
            target.mHalfExtent = Vec3(0.2f + 0.25f * unit(setupRandom), 0.2f + 0.25f * unit(setupRandom),
                                      0.2f + 0.25f * unit(setupRandom));
            body.mShape = BoxShape::Create(target.mHalfExtent).Value();
        }
        else
        {
            target.mSphere = true;
            target.mRadius = 0.25f + 0.2f * unit(setupRandom);
            body.mShape = SphereShape::Create(target.mRadius).Value();
        }
        target.mID = addPermanent(body, Activation::Activate);
        targets.push_back(target);
    }

    // The boxes moved by hand, near the +z wall (they land among the pile bodies that reach it)
    std::vector<BodyID> handMoved;
    for (uint32_t i = 0; i < inConfig.mNumHandMoved; ++i)
    {
        BodyCreationSettings body;
        body.mShape = BoxShape::Create(Vec3(0.35f, 0.35f, 0.35f)).Value();
        body.mPosition = Vec3(-10.0f + 2.5f * float(i), 2.0f, 10.0f);
        body.mAllowSleeping = false;
        handMoved.push_back(addPermanent(body, Activation::Activate));
        targets.push_back({handMoved.back(), false, Vec3(0.35f, 0.35f, 0.35f), 0.0f});
    }
    result.mPermanentBodies = uint32_t(permanent.size());

    // Relaxed for the stop flag and the counters: no data is published through them. The others say why
    std::atomic<bool> stop{false};
    std::atomic<bool> stepping{false}; // Seq-cst: only a figure, but the plainest to reason about
    std::atomic<uint64_t> updates{0}, fullRebuilds{0}, kinematicChanges{0}, handMoves{0}, churnBatches{0},
        failedCalls{result.mFailedCalls};
    std::atomic<uint64_t> checks{0}, checksDuringStep{0}, misses{0}, inconclusive{0}, inconclusiveNotFound{0},
        staleIDs{0}, duplicates{0}, tornPoses{0}, unreadable{0}, probes{0}, churnedReported{0},
        removedDuringQuery{0};

    std::mutex failureMutex; // Guards failures
    std::vector<std::string> failures;
    auto recordFailure = [&](std::string inWhat)
    {
        const std::lock_guard lock(failureMutex);
        if (failures.size() < 10) failures.push_back(std::move(inWhat));
    };

    // The churned bodies' states (cCreated, cInWorld, or the removal clock tick once RemoveBody returned),
    // and the clock: ticked after each removal is recorded. Guarded by churnMutex; the clock is also read
    // without it (acquire, pairs with the release store under the mutex): a query that reads tick t before it
    // starts knows that every removal recorded with a tick <= t had returned before it started
    std::mutex churnMutex;
    std::unordered_map<BodyID, uint64_t> churnState;
    std::atomic<uint64_t> removalClock{0};

    auto stepThread = [&]
    {
        uint64_t count = 0, rebuilds = 0, changes = 0, failed = 0;
        while (!stop.load(std::memory_order_relaxed))
        {
            stepping.store(true);
            const Status status =
                jobSystem ? system->Update(1.0f / 60.0f, 1, *jobSystem) : system->Update(1.0f / 60.0f);
            stepping.store(false);
            failed += status ? 0 : 1;
            ++count;
            // Release: the churn thread's waits read it (only as a pace, but a release costs nothing here)
            updates.store(count, std::memory_order_release);
            if (count % 16 == 0)
            {
                quadTree.RebuildAll();
                ++rebuilds;
            }
            // The pistons turn round at the ends of their stroke (read from their published pose: no lock)
            {
                const PoseReader reader(system->GetBodyManager());
                for (const Piston& piston : pistons)
                {
                    PublishedPose pose;
                    if (!reader.Read(piston.mID, pose)) continue;
                    const float out = pose.mTransform.mPosition.dot(piston.mOutwards);
                    const Result<Vec3> velocity = bodies.GetLinearVelocity(piston.mID);
                    if (!velocity)
                    {
                        ++failed;
                        continue;
                    }
                    const bool movingOut = velocity.Value().dot(piston.mOutwards) > 0.0f;
                    if ((out > cPistonOut && movingOut) || (out < cPistonIn && !movingOut))
                    {
                        failed +=
                            bodies.SetLinearVelocity(piston.mID, (movingOut ? -cPistonSpeed : cPistonSpeed) *
                                                                     piston.mOutwards)
                                ? 0
                                : 1;
                        ++changes;
                    }
                }
            }
            if (count % cPaddleTurnUpdates == 0)
                for (size_t i = 0; i < paddles.size(); ++i)
                {
                    const float sign = (count / cPaddleTurnUpdates) % 2 == 0 ? 1.0f : -1.0f;
                    failed += bodies.SetAngularVelocity(
                                  paddles[i], Vec3(0.0f, (i == 0 ? sign : -sign) * cPaddleSpin, 0.0f))
                                  ? 0
                                  : 1;
                    ++changes;
                }
        }
        fullRebuilds.store(rebuilds, std::memory_order_relaxed);
        kinematicChanges.store(changes, std::memory_order_relaxed);
        failedCalls.fetch_add(failed, std::memory_order_relaxed);
    };

    auto moverThread = [&]
    {
        std::mt19937 random(7);
        std::uniform_int_distribution<size_t> pick(0, handMoved.size() - 1);
        std::uniform_real_distribution<float> x(-12.0f, 12.0f), y(1.5f, 3.0f), z(8.0f, 12.5f);
        uint64_t count = 0, failed = 0;
        while (!stop.load(std::memory_order_relaxed))
        {
            const Vec3 position(x(random), y(random), z(random));
            failed += bodies.SetPositionAndRotation(handMoved[pick(random)], position, RandomRotation(random),
                                                    Activation::Activate)
                          ? 0
                          : 1;
            ++count;
            // At most a few thousand moves a second: each waits for the step's locks, and more would only
            // starve it
            std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
        handMoves.store(count, std::memory_order_relaxed);
        failedCalls.fetch_add(failed, std::memory_order_relaxed);
    };

    auto churnThread = [&]
    {
        std::mt19937 random(9);
        std::uniform_real_distribution<float> xz(-10.0f, 10.0f), sphereY(4.0f, 6.0f), plateY(6.5f, 7.5f);
        const ShapeRef sphere = SphereShape::Create(0.3f).Value();
        const ShapeRef plate = BoxShape::Create(Vec3(0.5f, 0.1f, 0.5f)).Value();
        std::vector<BodyID> batch;
        uint64_t count = 0, failed = 0;
        // Waits until the step thread has run inCount more updates (or the run stops)
        auto waitUpdates = [&](uint64_t inCount)
        {
            const uint64_t target = updates.load(std::memory_order_acquire) + inCount;
            while (!stop.load(std::memory_order_relaxed) && updates.load(std::memory_order_acquire) < target)
                std::this_thread::sleep_for(std::chrono::microseconds(100));
        };
        while (!stop.load(std::memory_order_relaxed))
        {
            batch.clear();
            for (uint32_t k = 0; k < inConfig.mChurnBatch; ++k)
            {
                BodyCreationSettings body;
                if (k % 2 == 0)
                {
                    body.mShape = sphere;
                    body.mPosition = Vec3(xz(random), sphereY(random), xz(random));
                }
                else
                {
                    body = StaticBox(Vec3(xz(random), plateY(random), xz(random)), Vec3(0.5f, 0.1f, 0.5f));
                    body.mShape = plate;
                }
                const Result<BodyID> id = bodies.CreateBody(body);
                if (!id)
                {
                    ++failed;
                    continue;
                }
                batch.push_back(id.Value());
            }
            {
                const std::lock_guard lock(churnMutex);
                for (const BodyID& id : batch)
                    churnState[id] = cCreated;
            }
            Result<BodyInterface::AddBatch> prepared = bodies.AddBodiesPrepare(batch);
            if (!prepared || !bodies.AddBodiesFinalize(prepared.Value(), Activation::Activate)) ++failed;
            {
                const std::lock_guard lock(churnMutex);
                for (const BodyID& id : batch)
                    churnState[id] = cInWorld;
            }
            // In the world for two steps, so the spheres fall, collide and get published
            waitUpdates(2);
            for (const BodyID& id : batch)
            {
                failed += bodies.RemoveBody(id) ? 0 : 1;
                const std::lock_guard lock(churnMutex);
                const uint64_t tick = removalClock.load(std::memory_order_relaxed) + 1; // Only written here
                churnState[id] = tick;
                removalClock.store(tick, std::memory_order_release);
            }
            for (const BodyID& id : batch)
                failed += bodies.DestroyBody(id) ? 0 : 1;
            ++count;
            waitUpdates(1); // A streaming rate: one batch per update at most
        }
        churnBatches.store(count, std::memory_order_relaxed);
        failedCalls.fetch_add(failed, std::memory_order_relaxed);
    };

    auto queryThread = [&](uint32_t inSeed)
    {
        const WorldQuery& query = system->GetWorldQuery();
        const BodyManager& manager = system->GetBodyManager();
        std::mt19937 random(inSeed);
        std::uniform_int_distribution<size_t> pick(0, targets.size() - 1);
        std::uniform_real_distribution<float> symmetric(-1.0f, 1.0f), probeXZ(-10.0f, 10.0f),
            probeY(4.0f, 7.5f);
        std::vector<BodyID> pointHits, boxHits, castHits, probeHits;
        std::vector<ShapeCastResult> castResults;
        const SphereShape castProbe(0.01f);
        uint64_t rounds = 0, count = 0, duringStep = 0, missed = 0, notChecked = 0, movedAway = 0, stale = 0,
                 twice = 0, torn = 0, notRead = 0, probeCount = 0, churnSeen = 0, churnGone = 0, failed = 0;

        // The stale-id check of one query's result (sorted by id, as every WorldQuery overlap result is);
        // inClockBefore: the removal clock read before the query started
        auto checkReported =
            [&](const std::vector<BodyID>& inHits, uint64_t inClockBefore, const char* inQuery)
        {
            const PoseReader reader(manager);
            for (size_t i = 0; i < inHits.size(); ++i)
            {
                const BodyID id = inHits[i];
                if (i > 0 && inHits[i - 1] == id)
                {
                    ++twice;
                    recordFailure(std::string(inQuery) + " reported body " + std::to_string(id.GetIndex()) +
                                  "/" + std::to_string(id.GetSequence()) + " twice");
                }
                const bool isPermanent = permanent.count(id) != 0;
                if (!isPermanent) ++churnSeen;
                PublishedPose pose;
                if (reader.Read(id, pose)) continue; // In the world now, under this very id
                const char* why = nullptr;
                if (isPermanent)
                    why = "is a permanent body that cannot be read";
                else
                {
                    const std::lock_guard lock(churnMutex);
                    const auto found = churnState.find(id);
                    if (found == churnState.end())
                        why = "was never created by this test";
                    else if (found->second == cCreated)
                        why = "was never added to the world";
                    else if (found->second != cInWorld && found->second <= inClockBefore)
                        why = "had been removed before the query started";
                }
                if (why == nullptr)
                {
                    ++churnGone; // Removed while the query ran (or being removed): reported with its last
                                 // pose
                    continue;
                }
                ++stale;
                recordFailure(std::string(inQuery) + " reported body " + std::to_string(id.GetIndex()) + "/" +
                              std::to_string(id.GetSequence()) + ", which " + why);
            }
        };

        while (!stop.load(std::memory_order_relaxed))
        {
            const Target& target = targets[pick(random)];
            const uint64_t clockBefore = removalClock.load(std::memory_order_acquire);
            const bool steppingBefore = stepping.load();
            PublishedPose before;
            {
                const PoseReader reader(manager);
                if (!reader.Read(target.mID, before))
                {
                    ++notRead;
                    recordFailure("the pose of permanent body " + std::to_string(target.mID.GetIndex()) +
                                  " could not be read");
                    continue;
                }
            }
            if (std::abs(before.mTransform.mRotation.norm() - 1.0f) > 1.0e-4f)
            {
                ++torn;
                recordFailure("body " + std::to_string(target.mID.GetIndex()) +
                              " published a rotation of norm " +
                              std::to_string(before.mTransform.mRotation.norm()));
            }

            // A point well inside the shape at the pose just read: within 0.9 of each half extent, or of the
            // radius
            Vec3 local;
            if (target.mSphere)
            {
                do
                    local = Vec3(symmetric(random), symmetric(random), symmetric(random));
                while (local.squaredNorm() > 1.0f);
                local *= 0.9f * target.mRadius;
            }
            else
                local = 0.9f * target.mHalfExtent.cwiseProduct(
                                   Vec3(symmetric(random), symmetric(random), symmetric(random)));
            const Vec3 point = before.mTransform * local;

            failed += query.CollidePoint(point, pointHits) ? 0 : 1;
            failed +=
                query.CollideAABox(AABB::FromCenterExtent(point, Vec3::Constant(0.01f)), boxHits) ? 0 : 1;
            // From beyond the shape's bounding sphere (the point is within it) plus the probe's radius, so
            // the probe starts outside the body and must touch it on its way to the point
            Vec3 side;
            do
                side = Vec3(symmetric(random), symmetric(random), symmetric(random));
            while (side.squaredNorm() > 1.0f || side.squaredNorm() < 0.01f);
            const float reach = 2.0f * (target.mSphere ? target.mRadius : target.mHalfExtent.norm()) + 0.05f;
            const Vec3 castFrom = point + reach * side.normalized();
            failed +=
                query.CastShapeAll(castProbe, {castFrom, Quat::Identity()}, point - castFrom, castResults)
                    ? 0
                    : 1;
            castHits.clear();
            for (const ShapeCastResult& result : castResults)
                castHits.push_back(result.mBody);
            std::sort(castHits.begin(), castHits.end());

            PublishedPose after;
            bool readAfter;
            {
                const PoseReader reader(manager);
                readAfter = reader.Read(target.mID, after);
            }
            const bool steppingAfter = stepping.load();
            if (!readAfter)
            {
                ++notRead;
                recordFailure("the pose of permanent body " + std::to_string(target.mID.GetIndex()) +
                              " could not be read after the query");
                continue;
            }
            if (after.mVersion != before.mVersion)
            {
                // Not checked: the body may have left the point. How often it did shows what a check catches
                notChecked += 3;
                for (const std::vector<BodyID>* hits : {&pointHits, &boxHits, &castHits})
                    movedAway += std::find(hits->begin(), hits->end(), target.mID) == hits->end() ? 1 : 0;
            }
            else
            {
                count += 3;
                if (steppingBefore || steppingAfter) duringStep += 3;
                const std::vector<BodyID>* hitLists[3] = {&pointHits, &boxHits, &castHits};
                const char* names[3] = {"CollidePoint", "CollideAABox", "CastShapeAll"};
                for (int k = 0; k < 3; ++k)
                {
                    const std::vector<BodyID>& hits = *hitLists[k];
                    if (std::find(hits.begin(), hits.end(), target.mID) != hits.end()) continue;
                    ++missed;
                    char text[512];
                    std::snprintf(
                        text, sizeof(text),
                        "%s missed body %u/%u (%s %s) at version %u: point (%.6f, %.6f, %.6f), local "
                        "(%.4f, %.4f, %.4f), pose (%.6f, %.6f, %.6f) rotation (%.6f, %.6f, %.6f, %.6f), "
                        "%zu bodies reported, Update running before/after: %d/%d",
                        names[k], target.mID.GetIndex(), target.mID.GetSequence(),
                        before.mMotionType == MotionType::Kinematic ? "kinematic" : "dynamic",
                        target.mSphere ? "sphere" : "box", before.mVersion, point.x(), point.y(), point.z(),
                        local.x(), local.y(), local.z(), before.mTransform.mPosition.x(),
                        before.mTransform.mPosition.y(), before.mTransform.mPosition.z(),
                        before.mTransform.mRotation.x(), before.mTransform.mRotation.y(),
                        before.mTransform.mRotation.z(), before.mTransform.mRotation.w(), hits.size(),
                        int(steppingBefore), int(steppingAfter));
                    recordFailure(text);
                }
            }
            checkReported(pointHits, clockBefore, "CollidePoint");
            checkReported(boxHits, clockBefore, "CollideAABox");
            checkReported(castHits, clockBefore, "CastShapeAll");

            // Every 8th round, a box among the churned bodies (the spheres falling, the plates above), so
            // that many of the ids checked are of bodies being added and removed
            if (++rounds % 8 == 0)
            {
                const uint64_t probeClock = removalClock.load(std::memory_order_acquire);
                const Vec3 center(probeXZ(random), probeY(random), probeXZ(random));
                failed += query.CollideAABox(AABB::FromCenterExtent(center, Vec3::Constant(cProbeHalfSize)),
                                             probeHits)
                              ? 0
                              : 1;
                checkReported(probeHits, probeClock, "probe CollideAABox");
                ++probeCount;
            }

            // The running counts, now and then, so the main thread can stop at the targets
            if (count >= 1024)
            {
                checks.fetch_add(count, std::memory_order_relaxed);
                checksDuringStep.fetch_add(duringStep, std::memory_order_relaxed);
                churnedReported.fetch_add(churnSeen, std::memory_order_relaxed);
                count = 0;
                duringStep = 0;
                churnSeen = 0;
            }
        }
        checks.fetch_add(count, std::memory_order_relaxed);
        checksDuringStep.fetch_add(duringStep, std::memory_order_relaxed);
        misses.fetch_add(missed, std::memory_order_relaxed);
        inconclusive.fetch_add(notChecked, std::memory_order_relaxed);
        inconclusiveNotFound.fetch_add(movedAway, std::memory_order_relaxed);
        staleIDs.fetch_add(stale, std::memory_order_relaxed);
        duplicates.fetch_add(twice, std::memory_order_relaxed);
        tornPoses.fetch_add(torn, std::memory_order_relaxed);
        unreadable.fetch_add(notRead, std::memory_order_relaxed);
        probes.fetch_add(probeCount, std::memory_order_relaxed);
        churnedReported.fetch_add(churnSeen, std::memory_order_relaxed);
        removedDuringQuery.fetch_add(churnGone, std::memory_order_relaxed);
        failedCalls.fetch_add(failed, std::memory_order_relaxed);
    };

    const auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> threads;
    for (uint32_t q = 0; q < inConfig.mNumQueryThreads; ++q)
        threads.emplace_back(queryThread, 100 + q);
    threads.emplace_back(stepThread);
    threads.emplace_back(moverThread);
    threads.emplace_back(churnThread);
    for (;;)
    {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        const auto elapsed = std::chrono::steady_clock::now() - start;
        if (elapsed >= inConfig.mMaxDuration) break;
        // The churn's check too: on a loaded machine the churn thread, which sleeps between its steps, got
        // one batch in before the other targets were met, and no query had seen a churned body yet
        if (elapsed >= inConfig.mMinDuration &&
            checks.load(std::memory_order_relaxed) >= inConfig.mTargetChecks &&
            updates.load(std::memory_order_relaxed) >= inConfig.mMinUpdates &&
            churnedReported.load(std::memory_order_relaxed) > 0)
            break;
    }
    stop.store(true, std::memory_order_relaxed);
    for (std::thread& thread : threads)
        thread.join();

    result.mSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.mChecks = checks.load();
    result.mChecksDuringStep = checksDuringStep.load();
    result.mMisses = misses.load();
    result.mInconclusive = inconclusive.load();
    result.mInconclusiveNotFound = inconclusiveNotFound.load();
    result.mStaleIDs = staleIDs.load();
    result.mDuplicates = duplicates.load();
    result.mTornPoses = tornPoses.load();
    result.mUnreadableTargets = unreadable.load();
    result.mProbes = probes.load();
    result.mChurnedReported = churnedReported.load();
    result.mRemovedDuringQuery = removedDuringQuery.load();
    result.mUpdates = updates.load();
    result.mFullRebuilds = fullRebuilds.load();
    result.mKinematicChanges = kinematicChanges.load();
    result.mHandMoves = handMoves.load();
    result.mChurnBatches = churnBatches.load();
    result.mFailedCalls = failedCalls.load();
    result.mRefusedStepCalls = quadTree.GetRefusedStepCalls();
    result.mBodiesAfter = system->GetBodyManager().GetNumBodies();
    result.mFailures = std::move(failures);
    // The scene did what the comment at the top says: the pile stayed between the walls and was moving
    result.mPileBodies = numPile;
    float speeds = 0.0f;
    for (size_t i = pileBegin; i < pileBegin + numPile; ++i)
    {
        const Target& target = targets[i];
        const Result<Vec3> position = bodies.GetPosition(target.mID);
        const Result<Vec3> velocity = bodies.GetLinearVelocity(target.mID);
        if (!position || !velocity) continue;
        const Vec3& p = position.Value();
        result.mPileInArena +=
            std::abs(p.x()) < cArenaHalf && std::abs(p.z()) < cArenaHalf && p.y() > 0.0f ? 1 : 0;
        speeds += velocity.Value().norm();
    }
    result.mPileMeanSpeed = speeds / float(std::max(numPile, 1u));
    return result;
}

/// The expectations every run of the stress makes, and its figures on stdout. inRequiredChecks: the fewest
/// checks the run must have made.
inline void ExpectNoMissedPublishedPoses(const PublishedPoseStressResult& inResult, uint64_t inRequiredChecks)
{
    std::printf(
        "[ figure   ] %llu checks (%llu while Update ran), %llu misses, %llu inconclusive (%llu of them not "
        "reporting their moved body), %llu stale ids, %llu duplicates, %llu torn poses in %.1f s\n",
        (unsigned long long)inResult.mChecks, (unsigned long long)inResult.mChecksDuringStep,
        (unsigned long long)inResult.mMisses, (unsigned long long)inResult.mInconclusive,
        (unsigned long long)inResult.mInconclusiveNotFound, (unsigned long long)inResult.mStaleIDs,
        (unsigned long long)inResult.mDuplicates, (unsigned long long)inResult.mTornPoses, inResult.mSeconds);
    std::printf(
        "[ figure   ] %llu updates (%llu full rebuilds), %llu kinematic velocity changes, %llu moves by "
        "hand, %llu churn batches; %llu probes; %llu churned ids reported, %llu of them removed during "
        "their query; pile at the end: %u of %u bodies inside the walls, mean speed %.2f m/s\n",
        (unsigned long long)inResult.mUpdates, (unsigned long long)inResult.mFullRebuilds,
        (unsigned long long)inResult.mKinematicChanges, (unsigned long long)inResult.mHandMoves,
        (unsigned long long)inResult.mChurnBatches, (unsigned long long)inResult.mProbes,
        (unsigned long long)inResult.mChurnedReported, (unsigned long long)inResult.mRemovedDuringQuery,
        inResult.mPileInArena, inResult.mPileBodies, inResult.mPileMeanSpeed);
    for (const std::string& failure : inResult.mFailures)
        ADD_FAILURE() << failure;
    EXPECT_EQ(inResult.mMisses, 0u);
    EXPECT_EQ(inResult.mStaleIDs, 0u);
    EXPECT_EQ(inResult.mDuplicates, 0u);
    EXPECT_EQ(inResult.mTornPoses, 0u);
    EXPECT_EQ(inResult.mUnreadableTargets, 0u);
    EXPECT_EQ(inResult.mFailedCalls, 0u);
    EXPECT_EQ(inResult.mRefusedStepCalls, 0u) << "a full rebuild overlapped a step's broad-phase update";
    EXPECT_GE(inResult.mChecks, inRequiredChecks);
    EXPECT_GT(inResult.mChecksDuringStep, 0u);
    EXPECT_GT(inResult.mUpdates, 16u);
    EXPECT_GT(inResult.mFullRebuilds, 0u);
    EXPECT_GT(inResult.mKinematicChanges, 0u);
    EXPECT_GT(inResult.mHandMoves, 0u);
    EXPECT_GT(inResult.mChurnBatches, 0u);
    EXPECT_GT(inResult.mChurnedReported, 0u) << "the stale-id check saw no churned body";
    // Every churned body was removed and destroyed again
    EXPECT_EQ(inResult.mBodiesAfter, inResult.mPermanentBodies);
    EXPECT_EQ(inResult.mPileInArena, inResult.mPileBodies);
}

} // namespace cairn::test
