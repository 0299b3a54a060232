// Queries must not allocate: they run on many threads at once and in hot paths (character controllers, the
// navmesh collector). The test program's global operator new counts (common/AllocationCounter); after a
// warm-up, 1,000 queries of each kind (and pair searches) on every broad phase must allocate nothing.

#include "broadphase/BroadPhaseBruteForce.h"
#include "broadphase/BroadPhaseGlobalMutex.h"
#include "broadphase/BroadPhaseQuadTree.h"
#include "common/AllocationCounter.h"

#include <gtest/gtest.h>
#include <random>

namespace cairn
{
using namespace cairn::physics;
namespace
{

/// Runs 1,000 queries of each kind plus 10 pair searches; returns the number of hits (so the work is not
/// empty).
uint64_t RunQueries(const BroadPhase& inBroadPhase, const std::vector<BodyID>& inActive)
{
    std::mt19937 random(7);
    std::uniform_real_distribution<float> coordinate(0.0f, 100.0f);
    const LayerSetup layers = LayerSetup::CreateDefault();
    uint64_t hits = 0;
    for (int query = 0; query < 1000; ++query)
    {
        const Vec3 point(coordinate(random), coordinate(random) * 0.1f, coordinate(random));
        auto visit = [&](BodyID) { ++hits; };
        auto visitRay = [&](BodyID, float inFraction)
        {
            ++hits;
            return inFraction;
        };
        inBroadPhase.CollideAABox(AABB::FromCenterExtent(point, Vec3::Constant(3.0f)), {}, visit);
        inBroadPhase.CollideSphere(point, 3.0f, {}, visit);
        inBroadPhase.CollidePoint(point, {}, visit);
        inBroadPhase.CastRay({point, Vec3(20.0f, -1.0f, 5.0f)}, {}, visitRay);
        inBroadPhase.CastAABox(AABB::FromCenterExtent(point, Vec3::Constant(0.5f)), Vec3(-10.0f, 0.0f, 20.0f),
                               {}, visitRay);
    }
    for (int search = 0; search < 10; ++search)
        inBroadPhase.FindCollidingPairs(inActive, layers, [&](BodyID, BodyID) { ++hits; });
    return hits;
}

/// A broad phase with 2,000 bodies in a 100 m square, a third of them moving and active, some moved since the
/// last Update so that the dirty path runs too.
void Populate(BroadPhase& ioBroadPhase, std::vector<BodyID>& outActive)
{
    std::mt19937 random(3);
    std::uniform_real_distribution<float> coordinate(0.0f, 100.0f);
    std::uniform_real_distribution<float> size(0.2f, 3.0f);
    std::vector<BroadPhaseBody> bodies;
    for (uint32_t index = 0; index < 2000; ++index)
    {
        const Vec3 min(coordinate(random), coordinate(random) * 0.1f, coordinate(random));
        const ObjectLayer layer = index % 3 == 0 ? Layers::cMoving : Layers::cStatic;
        bodies.push_back(
            {BodyID(index, 1), AABB(min, min + Vec3(size(random), size(random), size(random))), layer});
        if (layer == Layers::cMoving) outActive.push_back(bodies.back().mID);
    }
    ioBroadPhase.AddBodiesFinalize(ioBroadPhase.AddBodiesPrepare(bodies));
    ioBroadPhase.Update();
    for (BroadPhaseBody& body : bodies)
        body.mBounds =
            AABB(body.mBounds.mMin + Vec3(5.0f, 0.0f, 0.0f), body.mBounds.mMax + Vec3(5.0f, 0.0f, 0.0f));
    ioBroadPhase.NotifyBodiesAABBChanged(std::span(bodies).first(100));
}

void ExpectNoAllocations(BroadPhase& ioBroadPhase)
{
    std::vector<BodyID> active;
    Populate(ioBroadPhase, active);
    const uint64_t warmUpHits = RunQueries(ioBroadPhase, active);

    test::AllocationScope scope;
    const uint64_t hits = RunQueries(ioBroadPhase, active);
    const uint64_t allocations = scope.GetCount();

    EXPECT_EQ(allocations, 0u);
    EXPECT_EQ(hits, warmUpHits);
    EXPECT_GT(hits, 1000u);
}

TEST(BroadPhaseAllocationTest, CountingOperatorNewWorks)
{
    // Guards the test itself: if the replacement were not linked in, the checks below would pass vacuously
    test::AllocationScope scope;
    // volatile: the compiler may otherwise elide a new/delete pair
    std::vector<int>* volatile allocated = new std::vector<int>(10);
    const uint64_t allocations = scope.GetCount();
    delete allocated;
    EXPECT_EQ(allocations, 2u);
}

TEST(BroadPhaseAllocationTest, BruteForceQueriesDoNotAllocate)
{
    BroadPhaseBruteForce broadPhase;
    ExpectNoAllocations(broadPhase);
}

TEST(BroadPhaseAllocationTest, QuadTreeQueriesDoNotAllocate)
{
    BroadPhaseQuadTree broadPhase(2000, LayerSetup::CreateDefault());
    ExpectNoAllocations(broadPhase);
}

TEST(BroadPhaseAllocationTest, QuadTreeGlobalMutexQueriesDoNotAllocate)
{
    BroadPhaseGlobalMutex broadPhase(std::make_unique<BroadPhaseQuadTree>(2000, LayerSetup::CreateDefault()));
    ExpectNoAllocations(broadPhase);
}

} // namespace
} // namespace cairn
