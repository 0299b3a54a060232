// A sphere that just touches a box: the quad tree's 4-wide node test decides a tight slot by itself, and must
// round exactly as the scalar test of the other broad phases does, or the two disagree about bodies on the
// sphere's surface (found by QuadTreePropertyTest: a squared distance summed in another order was 1 ulp over
// the squared radius in one and equal to it in the other).

#include "cairn/physics/broadphase/BroadPhaseBruteForce.h"
#include "cairn/physics/broadphase/BroadPhaseOverlap.h"
#include "cairn/physics/broadphase/BroadPhaseQuadTree.h"

#include <cmath>
#include <gtest/gtest.h>
#include <random>

namespace cairn
{
namespace
{

TEST(SphereBoundaryTest, QuadTreeAndBruteForceAgreeOnSpheresThatJustTouch)
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

} // namespace
} // namespace cairn
