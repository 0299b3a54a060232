// Changing live bodies while other threads query and the world steps (issue 31): no query misses a body, or
// reports it twice, while its object layer, motion type, shape or place changes. Part of the test command and
// run under ThreadSanitizer in CI (the concurrency label). The single-threaded behaviour of each call is
// tests/physics/simulation/LiveBodyChangeTest.cpp and tests/physics/broadphase/BroadPhaseChangeLayerTest.cpp.

#include "broadphase/BroadPhaseGlobalMutex.h"
#include "broadphase/BroadPhaseQuadTree.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "common/MakePhysicsSystem.h"
#include "common/PublishedPoseStress.h"

#include <array>
#include <atomic>
#include <chrono>
#include <gtest/gtest.h>
#include <memory>
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

/// A failure seen on a worker thread, kept for the test thread to report (gtest asserts there).
class Failures
{
public:
    void Record(const std::string& inWhat)
    {
        const std::lock_guard lock(mMutex);
        if (mFirst.empty()) mFirst = inWhat;
        ++mCount;
    }
    std::string Describe() const
    {
        const std::lock_guard lock(mMutex);
        return std::to_string(mCount) + " failures, the first: " + mFirst;
    }
    uint64_t Count() const
    {
        const std::lock_guard lock(mMutex);
        return mCount;
    }

private:
    mutable std::mutex mMutex;
    std::string mFirst;
    uint64_t mCount = 0;
};

/// How long the runs go: about a second in Release; a sanitizer build keeps the time cap and needs fewer
/// checks.
struct RunLength
{
    Clock::duration mMin = std::chrono::milliseconds(1000);
    Clock::duration mMax = std::chrono::milliseconds(test::cSlowBuild ? 8000 : 20000);
    uint64_t mTargetChecks = test::cSlowBuild ? 3000 : 50000;
    uint64_t mTargetChanges = test::cSlowBuild ? 300 : 2000; ///< Calls that change bodies

    /// Waits until the run has gone mMin and both counters reached their targets, or mMax, or a failure.
    void Wait(const std::atomic<uint64_t>& inChecks, const std::atomic<uint64_t>& inChanges,
              const Failures& inFailures) const
    {
        const Clock::time_point start = Clock::now();
        // Relaxed: progress only
        auto done = [&]
        {
            return Clock::now() - start >= mMin &&
                   inChecks.load(std::memory_order_relaxed) >= mTargetChecks &&
                   inChanges.load(std::memory_order_relaxed) >= mTargetChanges;
        };
        while (Clock::now() - start < mMax && !done() && inFailures.Count() == 0)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
};

/// The layers a changing body cycles through: from one broad-phase layer to the other (static and moving or
/// debris) and within one (moving and debris), both ways.
constexpr std::array<ObjectLayer, 6> cLayerCycle{Layers::cStatic, Layers::cMoving, Layers::cDebris,
                                                 Layers::cStatic, Layers::cDebris, Layers::cMoving};

/// ChangeBodyLayer against queries and rebuilds on a bare broad phase: bodies flip between the two trees,
/// another thread moves other bodies and rebuilds, and two threads query each flipping body's bounds with
/// every kind of query. A query whose filter takes the body's layer as the change's callback last set it (the
/// published layer), unchanged across the query, finds it exactly once; a query of every layer always does.
void RunBroadPhaseLayerFlips(BroadPhase& ioBroadPhase, FunctionRef<void()> inUpdate,
                             const BroadPhaseQuadTree& inTree)
{
    constexpr uint32_t cNumFlipping = 16, cNumOthers = 600;
    std::vector<BroadPhaseBody> flipping, others;
    for (uint32_t i = 0; i < cNumFlipping; ++i)
    {
        const Vec3 p(float(i) * 3.0f, 0.0f, -10.0f);
        flipping.push_back({BodyID(i, 1), AABB(p, p + Vec3::Constant(1.0f)), Layers::cStatic});
    }
    for (uint32_t i = 0; i < cNumOthers; ++i)
    {
        const Vec3 p(float(i % 30) * 1.5f, float(i / 300), float(i / 30 % 10) * 1.5f);
        others.push_back({BodyID(cNumFlipping + i, 1), AABB(p, p + Vec3::Constant(1.2f)),
                          i % 2 ? Layers::cMoving : Layers::cStatic});
    }
    ioBroadPhase.AddBodiesFinalize(ioBroadPhase.AddBodiesPrepare(flipping));
    ioBroadPhase.AddBodiesFinalize(ioBroadPhase.AddBodiesPrepare(others));

    // Per flipping body: the layer its last change's callback set, and how many callbacks ran, both written
    // by the changer inside the callback (the published layer of a body interface's change)
    std::array<std::atomic<uint32_t>, cNumFlipping> published{}; // layer | callbacks << 8
    std::atomic<bool> stop{false};
    std::atomic<uint64_t> changes{0}, checks{0}, updates{0};
    Failures failures;
    const RunLength length;

    std::thread changer(
        [&]
        {
            uint64_t count = 0, lastUpdate = 0;
            // Relaxed: a stop flag only
            for (uint32_t round = 1; !stop.load(std::memory_order_relaxed); ++round)
            {
                // A round of changes per update at most: each change takes a node in its new tree until a
                // rebuild, as an add does, and a world changes bodies between its steps, not thousands in one
                // (relaxed: a pace, no data hangs on it)
                while (updates.load(std::memory_order_relaxed) == lastUpdate &&
                       !stop.load(std::memory_order_relaxed))
                    std::this_thread::yield();
                lastUpdate = updates.load(std::memory_order_relaxed);
                for (uint32_t i = 0; i < cNumFlipping; ++i)
                {
                    const ObjectLayer layer = cLayerCycle[(round + i) % cLayerCycle.size()];
                    const bool changed = ioBroadPhase.ChangeBodyLayer(
                        flipping[i].mID, layer,
                        [&]
                        {
                            // Relaxed load: only this thread writes it. Release: a query that acquires the
                            // new value runs after the body is findable under the new layer
                            const uint32_t callbacks =
                                (published[i].load(std::memory_order_relaxed) >> 8) + 1;
                            published[i].store(layer | callbacks << 8, std::memory_order_release);
                        });
                    if (!changed) failures.Record("ChangeBodyLayer refused body " + std::to_string(i));
                    // Relaxed: progress for the test thread, and the total after the joins
                    changes.store(++count, std::memory_order_relaxed);
                }
            }
        });
    std::thread updater(
        [&]
        {
            std::mt19937 random(7);
            std::uniform_real_distribution<float> nudge(-0.05f, 0.05f);
            uint64_t count = 0;
            while (!stop.load(std::memory_order_relaxed)) // Relaxed: a stop flag only
            {
                for (BroadPhaseBody& body : others)
                    if (random() % 8 == 0)
                    {
                        const Vec3 by(nudge(random), nudge(random), nudge(random));
                        body.mBounds = AABB(body.mBounds.mMin + by, body.mBounds.mMax + by);
                    }
                ioBroadPhase.NotifyBodiesAABBChanged(others);
                inUpdate();
                // Relaxed: the changer's pace only
                updates.store(++count, std::memory_order_relaxed);
            }
        });
    auto query = [&](uint32_t inSeed)
    {
        std::mt19937 random(inSeed);
        uint64_t count = 0;
        std::vector<BodyID> hits;
        while (!stop.load(std::memory_order_relaxed)) // Relaxed: a stop flag only
        {
            const uint32_t i = random() % cNumFlipping;
            const BroadPhaseBody& body = flipping[i];
            // Acquire: pairs with the callback's release (the body is findable under that layer by then)
            const uint32_t before = published[i].load(std::memory_order_acquire);
            // Every layer, or a random set that holds the published layer (one tree or both)
            const bool everyLayer = random() % 2 == 0;
            const ObjectLayerMask mask =
                everyLayer ? cAllObjectLayers : (ObjectLayerMask(1) << (before & 0xff)) | (random() & 0xf);
            const BroadPhaseQueryFilter filter{mask};
            hits.clear();
            auto visit = [&](BodyID inID)
            {
                if (inID == body.mID) hits.push_back(inID);
            };
            auto visitCast = [&](BodyID inID, float)
            {
                visit(inID);
                return 1.0f;
            };
            const Vec3 centre = body.mBounds.Center();
            const char* kinds[] = {"box", "sphere", "point", "ray", "swept box"};
            const uint32_t kind = random() % 5;
            switch (kind)
            {
            case 0:
                ioBroadPhase.CollideAABox(body.mBounds.Expanded(-0.2f), filter, visit);
                break;
            case 1:
                ioBroadPhase.CollideSphere(centre, 0.3f, filter, visit);
                break;
            case 2:
                ioBroadPhase.CollidePoint(centre, filter, visit);
                break;
            case 3:
                ioBroadPhase.CastRay({centre - Vec3(0, 5, 0), Vec3(0, 10, 0)}, filter, visitCast);
                break;
            default:
                ioBroadPhase.CastAABox(AABB(centre - Vec3::Constant(0.1f), centre + Vec3::Constant(0.1f)),
                                       Vec3(0, 0, 3), filter, visitCast);
                break;
            }
            const uint32_t after = published[i].load(std::memory_order_acquire); // As above
            // A filter of every layer finds it always; another one while the published layer stood still
            if (!everyLayer && after != before) continue;
            if (hits.size() != 1)
                failures.Record(std::string(kinds[kind]) + " query found flipping body " + std::to_string(i) +
                                " " + std::to_string(hits.size()) + " times (layer " +
                                std::to_string(before & 0xff) +
                                (everyLayer ? ", every layer" : ", its layer") + ")");
            // Relaxed: progress for the test thread, and the total after the joins
            if (++count % 64 == 0) checks.fetch_add(64, std::memory_order_relaxed);
        }
        checks.fetch_add(count % 64, std::memory_order_relaxed); // As above
    };
    std::thread first(query, 11), second(query, 12);
    length.Wait(checks, changes, failures);
    stop.store(true, std::memory_order_relaxed); // Relaxed: a stop flag; the joins order the rest
    for (std::thread* thread : {&changer, &updater, &first, &second})
        thread->join();

    EXPECT_EQ(failures.Count(), 0u) << failures.Describe();
    EXPECT_GE(checks.load(), test::cSlowBuild ? 500u : 5000u);
    EXPECT_GE(changes.load(), 100u);
    EXPECT_GE(updates.load(), 10u);
    EXPECT_TRUE(inTree.Validate());
    EXPECT_EQ(ioBroadPhase.GetBodyCount(), cNumFlipping + cNumOthers);
    for (uint32_t i = 0; i < cNumFlipping; ++i)
    {
        // Each in the layer of its last callback, found there once
        const ObjectLayer layer = ObjectLayer(published[i].load() & 0xff);
        uint32_t found = 0;
        ioBroadPhase.CollideAABox(flipping[i].mBounds, {ObjectLayerMask(1) << layer},
                                  [&](BodyID inID) { found += inID == flipping[i].mID ? 1 : 0; });
        EXPECT_EQ(found, 1u) << "body " << i;
    }
}

TEST(LiveBodyChangeConcurrencyTest, BroadPhaseLayerFlipsNeverMissOrDoubleABody)
{
    BroadPhaseQuadTree broadPhase(1000, LayerSetup::CreateDefault());
    RunBroadPhaseLayerFlips(
        broadPhase, [&] { broadPhase.Update(); }, broadPhase);
}

TEST(LiveBodyChangeConcurrencyTest, BroadPhaseLayerFlipsBehindTheGlobalMutex)
{
    auto owned = std::make_unique<BroadPhaseQuadTree>(1000, LayerSetup::CreateDefault());
    const BroadPhaseQuadTree& quadTree = *owned;
    BroadPhaseGlobalMutex broadPhase(std::move(owned));
    RunBroadPhaseLayerFlips(
        broadPhase, [&] { broadPhase.Update(); }, quadTree);
}

/// The world: a floor, and boxes and spheres that one thread changes (motion type, object layer, shape,
/// place, kinematic moves) while the world steps back to back and two threads check each body's published
/// pose against the broad phase: a query over the pose's bounds, unchanged across the query, finds the body
/// once under every layer and under the pose's own layer.
TEST(LiveBodyChangeConcurrencyTest, ChangesWhileTheWorldStepsAndQueriesRun)
{
    PhysicsSettings settings;
    settings.mMaxBodies = 256;
    const std::unique_ptr<PhysicsSystem> system = test::MakePhysicsSystem(settings);
    BodyInterface& bodies = system->GetBodyInterface();
    {
        BodyCreationSettings floor;
        floor.mShape = BoxShape::Create(Vec3(40, 1, 40)).Value();
        floor.mPosition = Vec3(0, -1, 0);
        floor.mMotionType = MotionType::Static;
        floor.mObjectLayer = Layers::cStatic;
        ASSERT_TRUE(bodies.CreateAndAddBody(floor, Activation::DontActivate).IsOk());
    }
    const std::array<ShapeRef, 3> shapes{BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value(),
                                         BoxShape::Create(Vec3(0.8f, 0.3f, 0.6f)).Value(),
                                         SphereShape::Create(0.6f).Value()};
    constexpr uint32_t cNumChanged = 24;
    std::vector<BodyID> changed;
    for (uint32_t i = 0; i < cNumChanged; ++i)
    {
        BodyCreationSettings body;
        body.mShape = shapes[i % shapes.size()];
        body.mPosition = Vec3(float(i % 6) * 4.0f - 10.0f, 0.5f + float(i % 3), float(i / 6) * 4.0f - 8.0f);
        body.mMotionType = i % 3 == 0 ? MotionType::Static : MotionType::Dynamic;
        body.mObjectLayer = i % 3 == 0 ? Layers::cStatic : Layers::cMoving;
        changed.push_back(bodies.CreateAndAddBody(body, Activation::Activate).Value());
    }

    std::atomic<bool> stop{false};
    std::atomic<uint64_t> steps{0}, calls{0}, checks{0}, unchecked{0};
    Failures failures;
    const RunLength length;

    std::thread stepper(
        [&]
        {
            uint64_t count = 0;
            while (!stop.load(std::memory_order_relaxed)) // Relaxed: a stop flag only
            {
                if (Status status = system->Update(1.0f / 60.0f); !status)
                    failures.Record("Update: " + status.GetError().mMessage);
                ++count;
                // Relaxed: progress for the test thread
                steps.store(count, std::memory_order_relaxed);
            }
        });
    std::thread changer(
        [&]
        {
            std::mt19937 random(5);
            std::uniform_real_distribution<float> place(-12.0f, 12.0f), height(0.5f, 3.0f),
                angle(-0.3f, 0.3f);
            const std::array<ObjectLayer, 3> layers{Layers::cStatic, Layers::cMoving, Layers::cDebris};
            const std::array<MotionType, 3> types{MotionType::Static, MotionType::Kinematic,
                                                  MotionType::Dynamic};
            uint64_t count = 0;
            while (!stop.load(std::memory_order_relaxed)) // Relaxed: a stop flag only
            {
                const BodyID id = changed[random() % cNumChanged];
                Status status;
                const uint32_t op = random() % 6;
                switch (op)
                {
                case 0:
                    status = bodies.SetMotionType(id, types[random() % 3], Activation::Activate);
                    break;
                case 1:
                case 2:
                    status = bodies.SetObjectLayer(id, layers[random() % 3]);
                    break;
                case 3:
                    status = bodies.SetPosition(id, Vec3(place(random), height(random), place(random)),
                                                Activation::Activate);
                    break;
                case 4:
                    status =
                        bodies.SetShape(id, shapes[random() % shapes.size()], true, Activation::Activate);
                    break;
                default:
                {
                    // A kinematic body glides a little; any other refuses with InvalidArgument
                    const Vec3 at = bodies.GetPosition(id).Value();
                    status = bodies.MoveKinematic(id, at + Vec3(angle(random), 0, angle(random)),
                                                  Quat(Eigen::AngleAxisf(angle(random), Vec3::UnitY())),
                                                  1.0f / 60.0f);
                    if (!status && status.GetError().mCode == ErrorCode::InvalidArgument)
                        status = Status::Ok();
                    break;
                }
                }
                if (!status)
                    failures.Record("change " + std::to_string(op) + " of body " +
                                    std::to_string(id.GetIndex()) + ": " + status.GetError().mMessage);
                // Relaxed: progress for the test thread, and the total after the joins
                calls.store(++count, std::memory_order_relaxed);
                if (count % 8 == 0)
                    std::this_thread::yield(); // Let the step take the body locks now and then
            }
        });
    auto query = [&](uint32_t inSeed)
    {
        std::mt19937 random(inSeed);
        const BroadPhase& broadPhase = system->GetBroadPhase();
        const BodyManager& manager = system->GetBodyManager();
        uint64_t count = 0, skipped = 0;
        while (!stop.load(std::memory_order_relaxed)) // Relaxed: a stop flag only
        {
            const BodyID id = changed[random() % cNumChanged];
            // The reader keeps the shape of the pose alive for the length of the check
            const PoseReader reader(manager);
            PublishedPose before, after;
            if (!reader.Read(id, before))
            {
                failures.Record("body " + std::to_string(id.GetIndex()) + " could not be read");
                continue;
            }
            // A box well inside the published shape's bounds
            const AABB bounds = before.mShape->GetWorldBounds(before.mTransform);
            const AABB probe(bounds.Center() - 0.3f * bounds.HalfExtent(),
                             bounds.Center() + 0.3f * bounds.HalfExtent());
            uint32_t everyLayer = 0, ownLayer = 0;
            broadPhase.CollideAABox(probe, {}, [&](BodyID inID) { everyLayer += inID == id ? 1 : 0; });
            broadPhase.CollideAABox(probe, {ObjectLayerMask(1) << before.mLayer},
                                    [&](BodyID inID) { ownLayer += inID == id ? 1 : 0; });
            if (!reader.Read(id, after) || after.mVersion != before.mVersion)
            {
                ++skipped; // Published again meanwhile: the broad phase may hold either pose
                continue;
            }
            if (everyLayer != 1 || ownLayer != 1)
                failures.Record("body " + std::to_string(id.GetIndex()) + " (layer " +
                                std::to_string(before.mLayer) + ", motion type " +
                                std::to_string(int(before.mMotionType)) + ") found " +
                                std::to_string(everyLayer) + " times under every layer and " +
                                std::to_string(ownLayer) + " under its own");
            // Relaxed: progress for the test thread, and the total after the joins
            if (++count % 64 == 0) checks.fetch_add(64, std::memory_order_relaxed);
        }
        checks.fetch_add(count % 64, std::memory_order_relaxed); // As above
        unchecked.fetch_add(skipped, std::memory_order_relaxed); // As above
    };
    std::thread first(query, 21), second(query, 22);
    length.Wait(checks, calls, failures);
    stop.store(true, std::memory_order_relaxed); // Relaxed: a stop flag; the joins order the rest
    for (std::thread* thread : {&stepper, &changer, &first, &second})
        thread->join();

    EXPECT_EQ(failures.Count(), 0u) << failures.Describe();
    EXPECT_GE(checks.load(), test::cSlowBuild ? 500u : 5000u) << unchecked.load() << " unchecked";
    EXPECT_GE(calls.load(), 100u);
    EXPECT_GE(steps.load(), 10u);
    EXPECT_TRUE(dynamic_cast<const BroadPhaseQuadTree&>(system->GetBroadPhase()).Validate());
    for (const BodyID& id : changed)
    {
        const Vec3 position = bodies.GetPosition(id).Value();
        EXPECT_TRUE(position.allFinite()) << "body " << id.GetIndex();
        const bool active = bodies.IsActive(id).Value();
        PublishedPose pose;
        const PoseReader reader(system->GetBodyManager());
        ASSERT_TRUE(reader.Read(id, pose));
        EXPECT_FALSE(active && pose.mMotionType == MotionType::Static) << "a static body in the active list";
    }
}

} // namespace
} // namespace cairn
