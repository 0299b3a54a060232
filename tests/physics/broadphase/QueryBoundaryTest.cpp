// Queries that just touch a box (spheres, rays, swept boxes): the quad tree's 4-wide node tests decide a
// tight slot by themselves, and must round exactly as the scalar tests of the other broad phases do, or the
// two disagree about bodies on the query's surface (found by QuadTreePropertyTest: a squared distance summed
// in another order was 1 ulp over the squared radius in one and equal to it in the other).

#include "broadphase/BroadPhaseBruteForce.h"
#include "broadphase/BroadPhaseOverlap.h"
#include "broadphase/BroadPhaseQuadTree.h"

#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>
#include <random>
#include <utility>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

using Hits = std::vector<std::pair<BodyID, float>>;

/// A cast's visitor that keeps every hit and its fraction, and never shortens the cast.
auto CollectInto(Hits& outHits)
{
    return [&outHits](BodyID inID, float inFraction)
    {
        outHits.emplace_back(inID, inFraction);
        return 1.0f;
    };
}

/// A random corner of inBox, or a random point on one of its edges, where a query's entry and exit meet.
Vec3 CornerOrEdgePoint(const AABB& inBox, std::mt19937& ioRandom)
{
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    Vec3 point((ioRandom() & 1) ? inBox.mMax.x() : inBox.mMin.x(),
               (ioRandom() & 1) ? inBox.mMax.y() : inBox.mMin.y(),
               (ioRandom() & 1) ? inBox.mMax.z() : inBox.mMin.z());
    const int edgeAxis = int(ioRandom() % 4);
    if (edgeAxis < 3)
        point[edgeAxis] = inBox.mMin[edgeAxis] + unit(ioRandom) * (inBox.mMax - inBox.mMin)[edgeAxis];
    return point;
}

TEST(QueryBoundaryTest, QuadTreeAndBruteForceAgreeOnSpheresThatJustTouch)
{
    std::mt19937 random(7);
    std::uniform_real_distribution<float> coordinate(-20.0f, 20.0f), size(0.1f, 3.0f);
    int touching = 0; // Cases where the radius lands on the squared distance (within an ulp or two)
    for (int trial = 0; trial < 4000; ++trial)
    {
        const Vec3 min(coordinate(random), coordinate(random), coordinate(random));
        const AABB box(min, min + Vec3(size(random), size(random), size(random)));
        const Vec3 center(coordinate(random), coordinate(random), coordinate(random));
        const Vec3 closest = center.cwiseMax(box.mMin).cwiseMin(box.mMax);
        const float distance = (center - closest).norm();
        if (distance == 0.0f) continue;

        BroadPhaseBruteForce bruteForce;
        BroadPhaseQuadTree quadTree(16, LayerSetup::CreateDefault());
        const BroadPhaseBody body{BodyID(3, 1), box, Layers::cStatic};
        bruteForce.AddBodiesFinalize(bruteForce.AddBodiesPrepare({&body, 1}));
        quadTree.AddBodiesFinalize(quadTree.AddBodiesPrepare({&body, 1}));
        // Radii around the distance, a few ulps either way
        float radius = distance;
        for (int step = 0; step < 3; ++step)
            radius = std::nextafter(radius, 0.0f);
        for (int step = 0; step < 7; ++step, radius = std::nextafter(radius, 100.0f))
        {
            int bruteForceHits = 0, quadTreeHits = 0;
            bruteForce.CollideSphere(center, radius, {}, [&](BodyID) { ++bruteForceHits; });
            quadTree.CollideSphere(center, radius, {}, [&](BodyID) { ++quadTreeHits; });
            ASSERT_EQ(bruteForceHits, quadTreeHits)
                << "trial " << trial << ", radius " << radius << " against a distance of " << distance;
            touching += bruteForceHits == 1 && !SphereOverlapsAABB(center, std::nextafter(radius, 0.0f), box);
        }
    }
    EXPECT_GT(touching, 1000); // The radii did straddle the surface
}

TEST(QueryBoundaryTest, QuadTreeAndBruteForceAgreeOnRaysThatGrazeABox)
{
    // The same for the ray's 4-wide slab test: rays aimed at a box's corners and edge points, where the entry
    // and exit fractions meet
    std::mt19937 random(11);
    std::uniform_real_distribution<float> coordinate(-20.0f, 20.0f), size(0.1f, 3.0f), unit(0.0f, 1.0f);
    int hits = 0;
    for (int trial = 0; trial < 4000; ++trial)
    {
        const Vec3 min(coordinate(random), coordinate(random), coordinate(random));
        const AABB box(min, min + Vec3(size(random), size(random), size(random)));
        BroadPhaseBruteForce bruteForce;
        BroadPhaseQuadTree quadTree(16, LayerSetup::CreateDefault());
        const BroadPhaseBody body{BodyID(3, 1), box, Layers::cStatic};
        bruteForce.AddBodiesFinalize(bruteForce.AddBodiesPrepare({&body, 1}));
        quadTree.AddBodiesFinalize(quadTree.AddBodiesPrepare({&body, 1}));
        const Vec3 target = CornerOrEdgePoint(box, random);
        const Vec3 origin(coordinate(random), coordinate(random), coordinate(random));
        const float reach = 0.5f + 1.5f * unit(random); // Short of, or past, the target
        const RayCast ray{origin, reach * (target - origin)};
        Hits bruteForceHits, quadTreeHits;
        bruteForce.CastRay(ray, {}, CollectInto(bruteForceHits));
        quadTree.CastRay(ray, {}, CollectInto(quadTreeHits));
        ASSERT_EQ(bruteForceHits, quadTreeHits) << "trial " << trial;
        hits += int(bruteForceHits.size());
    }
    EXPECT_GT(hits, 1000); // Many of the rays reach their corner or edge
}

TEST(QueryBoundaryTest, QuadTreeAndBruteForceAgreeOnBoxesSweptPastACorner)
{
    // The swept box's node test grows each slot by the box half extents in 4-wide code, the leaf test in
    // scalar code: aim the box centre at corners and edge points of the grown body box, where a rounding
    // difference between the two would lose a body that just touches
    std::mt19937 random(13);
    std::uniform_real_distribution<float> coordinate(-20.0f, 20.0f), size(0.1f, 3.0f), unit(0.0f, 1.0f);
    int hits = 0;
    for (int trial = 0; trial < 4000; ++trial)
    {
        BroadPhaseBruteForce bruteForce;
        BroadPhaseQuadTree quadTree(16, LayerSetup::CreateDefault());
        // A few bodies, so the tree has a node above the leaves whose slot encloses more than one body
        std::vector<BroadPhaseBody> bodies;
        for (uint32_t i = 0; i < 5; ++i)
        {
            const Vec3 min(coordinate(random), coordinate(random), coordinate(random));
            bodies.push_back({BodyID(i, 1), AABB(min, min + Vec3(size(random), size(random), size(random))),
                              Layers::cStatic});
        }
        bruteForce.AddBodiesFinalize(bruteForce.AddBodiesPrepare(bodies));
        quadTree.AddBodiesFinalize(quadTree.AddBodiesPrepare(bodies));

        const Vec3 halfExtent(0.5f * size(random), 0.5f * size(random), 0.5f * size(random));
        const AABB& target = bodies[random() % bodies.size()].mBounds;
        const AABB grown(target.mMin - halfExtent, target.mMax + halfExtent);
        const Vec3 aim = CornerOrEdgePoint(grown, random);
        const Vec3 start(coordinate(random), coordinate(random), coordinate(random));
        const AABB box(start - halfExtent, start + halfExtent);
        const Vec3 displacement = (0.5f + 1.5f * unit(random)) * (aim - start);

        Hits bruteForceHits, quadTreeHits;
        bruteForce.CastAABox(box, displacement, {}, CollectInto(bruteForceHits));
        quadTree.CastAABox(box, displacement, {}, CollectInto(quadTreeHits));
        std::sort(bruteForceHits.begin(), bruteForceHits.end());
        std::sort(quadTreeHits.begin(), quadTreeHits.end());
        ASSERT_EQ(bruteForceHits, quadTreeHits) << "trial " << trial;
        hits += int(bruteForceHits.size());
    }
    EXPECT_GT(hits, 1000); // Many of the sweeps reach their corner or edge
}

} // namespace
} // namespace cairn
