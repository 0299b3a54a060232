// BroadPhaseSortAndSweep against the brute-force oracle on random worlds: after every step of a random
// sequence of add batches, aborted batches, removes, moves (small ones that stay in their slot, jumps,
// object-layer changes that move a body to another broad-phase layer) and Update() calls, every query kind
// and FindCollidingPairs must return exactly the same sets (sorted vectors compared element by element, ray
// fractions included).

#include "cairn/physics/broadphase/BroadPhaseBruteForce.h"
#include "cairn/physics/broadphase/BroadPhaseSortAndSweep.h"
#include "common/TestRandom.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <random>
#include <utility>

namespace cairn
{
namespace
{

constexpr uint32_t cNumBodies = 10000;

/// Random worlds in a 250 m x 60 m x 250 m box; half the coordinates snapped to a 0.5 m grid so that touching
/// boxes and rays along faces are common.
class RandomWorld : public test::TestRandom
{
public:
    using TestRandom::TestRandom;

    /// Bounds of mixed sizes: points, small and medium boxes, and 1% wide ones (up to 80 m, like ground
    /// slabs).
    AABB Bounds()
    {
        const Vec3 min(Coordinate(0.0f, 250.0f), Coordinate(-5.0f, 55.0f), Coordinate(0.0f, 250.0f));
        Vec3 size;
        const float kind = Uniform(0.0f, 1.0f);
        if (kind < 0.02f)
            size = Vec3::Zero();
        else if (kind < 0.01f + 0.02f)
            size = Vec3(Uniform(20.0f, 80.0f), Uniform(0.5f, 2.0f), Uniform(20.0f, 80.0f));
        else if (kind < 0.9f)
            size = Vec3(Coordinate(0.1f, 3.0f), Coordinate(0.1f, 3.0f), Coordinate(0.1f, 3.0f));
        else
            size = Vec3(Coordinate(3.0f, 10.0f), Coordinate(0.5f, 10.0f), Coordinate(3.0f, 10.0f));
        return {min, min + size};
    }

    /// Any of the 4 object layers of the default setup.
    ObjectLayer Layer() { return ObjectLayer(Index(4)); }

    /// A random object-layer filter: all layers most of the time, else a random subset.
    ObjectLayerMask Mask() { return Chance(0.6f) ? cAllObjectLayers : ObjectLayerMask(Index(16)); }
};

using HitList = std::vector<BodyID>;
using RayHitList = std::vector<std::pair<BodyID, float>>;
using PairList = std::vector<std::pair<BodyID, BodyID>>;

HitList Sorted(HitList inHits)
{
    std::sort(inHits.begin(), inHits.end());
    return inHits;
}

/// Every query kind and the pair search of both broad phases, compared.
class Comparer
{
public:
    Comparer(const BroadPhase& inOracle, const BroadPhase& inTested) : mOracle(inOracle), mTested(inTested) {}

    HitList Box(const BroadPhase& inBroadPhase, const AABB& inBox, ObjectLayerMask inMask) const
    {
        HitList hits;
        inBroadPhase.CollideAABox(inBox, {inMask}, [&](BodyID inID) { hits.push_back(inID); });
        return Sorted(hits);
    }
    HitList Sphere(const BroadPhase& inBroadPhase, const Vec3& inCenter, float inRadius,
                   ObjectLayerMask inMask) const
    {
        HitList hits;
        inBroadPhase.CollideSphere(inCenter, inRadius, {inMask}, [&](BodyID inID) { hits.push_back(inID); });
        return Sorted(hits);
    }
    HitList Point(const BroadPhase& inBroadPhase, const Vec3& inPoint, ObjectLayerMask inMask) const
    {
        HitList hits;
        inBroadPhase.CollidePoint(inPoint, {inMask}, [&](BodyID inID) { hits.push_back(inID); });
        return Sorted(hits);
    }
    /// Full visiting: every body on the segment with its entry fraction.
    RayHitList Ray(const BroadPhase& inBroadPhase, const RayCast& inRay, ObjectLayerMask inMask) const
    {
        RayHitList hits;
        inBroadPhase.CastRay(inRay, {inMask},
                             [&](BodyID inID, float inFraction)
                             {
                                 hits.emplace_back(inID, inFraction);
                                 return 1.0f;
                             });
        std::sort(hits.begin(), hits.end());
        return hits;
    }
    /// Closest hit: the visitor prunes with each fraction it gets.
    float ClosestRay(const BroadPhase& inBroadPhase, const RayCast& inRay, ObjectLayerMask inMask) const
    {
        float closest = 2.0f;
        inBroadPhase.CastRay(inRay, {inMask},
                             [&](BodyID, float inFraction)
                             {
                                 closest = std::min(closest, inFraction);
                                 return inFraction;
                             });
        return closest;
    }
    RayHitList SweptBox(const BroadPhase& inBroadPhase, const AABB& inBox, const Vec3& inDisplacement,
                        ObjectLayerMask inMask) const
    {
        RayHitList hits;
        inBroadPhase.CastAABox(inBox, inDisplacement, {inMask},
                               [&](BodyID inID, float inFraction)
                               {
                                   hits.emplace_back(inID, inFraction);
                                   return 1.0f;
                               });
        std::sort(hits.begin(), hits.end());
        return hits;
    }
    PairList Pairs(const BroadPhase& inBroadPhase, std::span<const BodyID> inActive,
                   const LayerSetup& inLayers) const
    {
        PairList pairs;
        inBroadPhase.FindCollidingPairs(inActive, inLayers,
                                        [&](BodyID inA, BodyID inB) { pairs.emplace_back(inA, inB); });
        std::sort(pairs.begin(), pairs.end());
        return pairs;
    }

    /// Runs inQueries random queries of each kind plus one pair search; returns the number of hits seen (so
    /// the test can check that the queries are not trivially empty).
    size_t CompareAll(RandomWorld& ioRandom, int inQueries, std::span<const BodyID> inActive,
                      const LayerSetup& inLayers)
    {
        size_t hits = 0;
        for (int query = 0; query < inQueries; ++query)
        {
            const ObjectLayerMask mask = ioRandom.Mask();

            AABB box = ioRandom.Bounds();
            if (ioRandom.Chance(0.3f)) box = box.Expanded(ioRandom.Uniform(0.0f, 20.0f));
            const HitList boxHits = Box(mOracle, box, mask);
            EXPECT_EQ(boxHits, Box(mTested, box, mask)) << "box query " << query;

            const Vec3 center(ioRandom.Coordinate(0.0f, 250.0f), ioRandom.Coordinate(-5.0f, 55.0f),
                              ioRandom.Coordinate(0.0f, 250.0f));
            const float radius = ioRandom.Chance(0.1f) ? 0.0f : ioRandom.Coordinate(0.0f, 15.0f);
            const HitList sphereHits = Sphere(mOracle, center, radius, mask);
            EXPECT_EQ(sphereHits, Sphere(mTested, center, radius, mask)) << "sphere query " << query;

            // Points on body corners half of the time: exactly on a face
            const Vec3 point = ioRandom.Chance(0.5f) ? ioRandom.Bounds().mMin : center;
            const HitList pointHits = Point(mOracle, point, mask);
            EXPECT_EQ(pointHits, Point(mTested, point, mask)) << "point query " << query;

            // Rays: random, or along an axis from a grid point (through faces and along slab planes)
            RayCast ray{center, Vec3(ioRandom.Uniform(-60.0f, 60.0f), ioRandom.Uniform(-20.0f, 20.0f),
                                     ioRandom.Uniform(-60.0f, 60.0f))};
            if (ioRandom.Chance(0.3f))
            {
                ray.mDirection = Vec3::Zero();
                ray.mDirection[int(ioRandom.Index(3))] = ioRandom.Chance(0.5f) ? 80.0f : -80.0f;
            }
            const RayHitList rayHits = Ray(mOracle, ray, mask);
            EXPECT_EQ(rayHits, Ray(mTested, ray, mask)) << "ray " << query;
            EXPECT_EQ(ClosestRay(mOracle, ray, mask), ClosestRay(mTested, ray, mask))
                << "closest ray " << query;

            const AABB sweptBox = AABB::FromCenterExtent(center, Vec3(ioRandom.Coordinate(0.0f, 3.0f),
                                                                      ioRandom.Coordinate(0.0f, 3.0f),
                                                                      ioRandom.Coordinate(0.0f, 3.0f)));
            const RayHitList sweptHits = SweptBox(mOracle, sweptBox, ray.mDirection, mask);
            EXPECT_EQ(sweptHits, SweptBox(mTested, sweptBox, ray.mDirection, mask)) << "swept box " << query;

            hits += boxHits.size() + sphereHits.size() + pointHits.size() + rayHits.size() + sweptHits.size();
        }
        const PairList pairs = Pairs(mOracle, inActive, inLayers);
        EXPECT_EQ(pairs, Pairs(mTested, inActive, inLayers));
        return hits + pairs.size();
    }

    const BroadPhase& mOracle; ///< Brute force
    const BroadPhase& mTested; ///< The implementation under test
};

class BroadPhaseEquivalenceTest : public ::testing::TestWithParam<uint32_t>
{
};

TEST_P(BroadPhaseEquivalenceTest, RandomOperationSequences)
{
    RandomWorld random(GetParam());
    const LayerSetup layers = LayerSetup::CreateDefault();
    BroadPhaseBruteForce oracle;
    BroadPhaseSortAndSweep tested(cNumBodies, layers);
    BroadPhase* both[] = {&oracle, &tested};
    Comparer comparer(oracle, tested);

    // Each body index has a current sequence number; present[i] says whether it is added
    std::vector<uint32_t> sequence(cNumBodies, 1);
    std::vector<BroadPhaseBody> stored(cNumBodies);
    std::vector<bool> present(cNumBodies, false);
    auto makeBody = [&](uint32_t inIndex) {
        return BroadPhaseBody{BodyID(inIndex, sequence[inIndex]), random.Bounds(), random.Layer()};
    };

    // Start with most of the world in one batch
    std::vector<BroadPhaseBody> batch;
    for (uint32_t index = 0; index < cNumBodies; ++index)
        if (random.Chance(0.8f))
        {
            batch.push_back(makeBody(index));
            stored[index] = batch.back();
            present[index] = true;
        }
    for (BroadPhase* broadPhase : both)
        broadPhase->AddBodiesFinalize(broadPhase->AddBodiesPrepare(batch));

    size_t totalHits = 0;
    for (int step = 0; step < 40; ++step)
    {
        const int operation = int(random.Index(6));
        switch (operation)
        {
        case 0: // Add a batch of absent bodies (new sequence numbers), sometimes with a duplicate index in it
        case 1: // Abort a batch: nothing may be added
        {
            batch.clear();
            for (int i = 0; i < 200; ++i)
            {
                const uint32_t index = random.Index(cNumBodies);
                if (present[index]) continue;
                ++sequence[index];
                batch.push_back(makeBody(index));
                if (operation == 0)
                {
                    stored[index] = batch.back();
                    present[index] = true;
                }
            }
            for (BroadPhase* broadPhase : both)
            {
                BroadPhase::AddState state = broadPhase->AddBodiesPrepare(batch);
                if (operation == 0)
                    broadPhase->AddBodiesFinalize(state);
                else
                    broadPhase->AddBodiesAbort(state);
            }
            break;
        }
        case 2: // Remove present bodies, plus stale ids and absent ones (ignored)
        {
            std::vector<BodyID> removed;
            for (int i = 0; i < 300; ++i)
            {
                const uint32_t index = random.Index(cNumBodies);
                if (present[index] && random.Chance(0.9f))
                {
                    removed.push_back(stored[index].mID);
                    present[index] = false;
                }
                else
                    removed.push_back(BodyID(index, sequence[index] + 7)); // never present
            }
            for (BroadPhase* broadPhase : both)
                broadPhase->RemoveBodies(removed);
            break;
        }
        default: // Move bodies: small moves (stay in their slot), jumps, layer changes
        {
            std::vector<BroadPhaseBody> moved;
            for (int i = 0; i < 600; ++i)
            {
                const uint32_t index = random.Index(cNumBodies);
                if (!present[index]) continue;
                BroadPhaseBody body = stored[index];
                const float kind = random.Uniform(0.0f, 1.0f);
                if (kind < 0.6f)
                {
                    const Vec3 delta(random.Uniform(-0.4f, 0.4f), random.Uniform(-1.0f, 1.0f),
                                     random.Uniform(-0.4f, 0.4f));
                    body.mBounds = AABB(body.mBounds.mMin + delta, body.mBounds.mMax + delta);
                }
                else if (kind < 0.9f)
                    body.mBounds = random.Bounds();
                else
                    body.mLayer = random.Layer();
                stored[index] = body;
                moved.push_back(body);
            }
            for (BroadPhase* broadPhase : both)
                broadPhase->NotifyBodiesAABBChanged(moved);
            break;
        }
        }
        // Update sometimes, so that queries run both on fresh snapshots and with dirty/dead entries
        if (random.Chance(0.4f)) tested.Update();

        ASSERT_TRUE(tested.Validate()) << "step " << step;
        ASSERT_EQ(oracle.GetBodyCount(), tested.GetBodyCount()) << "step " << step;

        // Active bodies: present moving/debris/trigger bodies, a few static ones, some absent or stale ids
        std::vector<BodyID> active;
        for (uint32_t index = 0; index < cNumBodies; ++index)
        {
            if (present[index] && stored[index].mLayer != Layers::cStatic && random.Chance(0.15f))
                active.push_back(stored[index].mID);
            else if (present[index] && random.Chance(0.01f))
                active.push_back(stored[index].mID);
            else if (!present[index] && random.Chance(0.01f))
                active.push_back(BodyID(index, sequence[index]));
        }
        std::shuffle(active.begin(), active.end(), random.mRandom);
        totalHits += comparer.CompareAll(random, 30, active, layers);
        if (::testing::Test::HasFailure())
            FAIL() << "first difference at step " << step << " (operation " << operation << ")";
    }
    // The comparison is only meaningful if the queries find things
    EXPECT_GT(totalHits, 10000u);
}

INSTANTIATE_TEST_SUITE_P(Seeds, BroadPhaseEquivalenceTest, ::testing::Values(1u, 2u, 3u));

} // namespace
} // namespace cairn
