// Hand-made cases run on every broad phase: closed-interval semantics (touching counts), rays along axes and
// faces, swept boxes, layer filters, pairs reported once, aborted batches and ignored bad input. Every case
// runs before and after Update(), so the quad tree's linked sub-trees and its rebuilt trees both get tested.

#include "physics/broadphase/BroadPhaseKinds.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <limits>
#include <memory>

namespace cairn
{
using namespace cairn::physics;
namespace
{

using test::cA;
using test::cB;
using test::cC;
using test::cD;
using test::cUnitBox;

template <class T> class BroadPhaseCasesTest : public ::testing::Test
{
protected:
    void SetUp() override { mBroadPhase = test::MakeBroadPhase<T>(); }

    void Add(std::initializer_list<BroadPhaseBody> inBodies)
    {
        const std::vector<BroadPhaseBody> bodies(inBodies);
        mBroadPhase->AddBodiesFinalize(mBroadPhase->AddBodiesPrepare(bodies));
    }

    std::vector<BodyID> Box(const AABB& inBox, ObjectLayerMask inMask = cAllObjectLayers) const
    {
        std::vector<BodyID> hits;
        mBroadPhase->CollideAABox(inBox, {inMask}, [&](BodyID inID) { hits.push_back(inID); });
        std::sort(hits.begin(), hits.end());
        return hits;
    }
    std::vector<BodyID> Point(const Vec3& inPoint) const
    {
        std::vector<BodyID> hits;
        mBroadPhase->CollidePoint(inPoint, {}, [&](BodyID inID) { hits.push_back(inID); });
        return hits;
    }
    std::vector<BodyID> Sphere(const Vec3& inCenter, float inRadius) const
    {
        std::vector<BodyID> hits;
        mBroadPhase->CollideSphere(inCenter, inRadius, {}, [&](BodyID inID) { hits.push_back(inID); });
        return hits;
    }
    /// Every (body, fraction) on the ray, sorted by body.
    std::vector<std::pair<BodyID, float>> Ray(const Vec3& inOrigin, const Vec3& inDirection) const
    {
        std::vector<std::pair<BodyID, float>> hits;
        mBroadPhase->CastRay({inOrigin, inDirection}, {},
                             [&](BodyID inID, float inFraction)
                             {
                                 hits.emplace_back(inID, inFraction);
                                 return 1.0f;
                             });
        std::sort(hits.begin(), hits.end());
        return hits;
    }
    std::vector<std::pair<BodyID, BodyID>> Pairs(std::initializer_list<BodyID> inActive) const
    {
        std::vector<std::pair<BodyID, BodyID>> pairs;
        const std::vector<BodyID> active(inActive);
        mBroadPhase->FindCollidingPairs(active, LayerSetup::CreateDefault(),
                                        [&](BodyID inA, BodyID inB) { pairs.emplace_back(inA, inB); });
        std::sort(pairs.begin(), pairs.end());
        return pairs;
    }

    std::unique_ptr<BroadPhase> mBroadPhase;
};

TYPED_TEST_SUITE(BroadPhaseCasesTest, test::BroadPhaseKinds);

TYPED_TEST(BroadPhaseCasesTest, TouchingCountsAsOverlapping)
{
    this->Add({{cA, cUnitBox, Layers::cMoving}, {cB, AABB(Vec3(1, 0, 0), Vec3(2, 1, 1)), Layers::cMoving}});
    for (int pass = 0; pass < 2; ++pass)
    {
        // Query boxes touching a face, an edge, a corner; one just off the face
        EXPECT_EQ(this->Box(AABB(Vec3(-1, 0.2f, 0.2f), Vec3(0, 0.8f, 0.8f))), std::vector<BodyID>{cA});
        EXPECT_EQ(this->Box(AABB(Vec3(-1, -1, 0.5f), Vec3(0, 0, 0.6f))), std::vector<BodyID>{cA});
        EXPECT_EQ(this->Box(AABB(Vec3(2, 1, 1), Vec3(3, 3, 3))), std::vector<BodyID>{cB});
        EXPECT_TRUE(this->Box(AABB(Vec3(-1, 0, 0), Vec3(-1.0e-6f, 1, 1))).empty());
        // The shared face belongs to both
        EXPECT_EQ(this->Box(AABB(Vec3(1, 0.5f, 0.5f), Vec3(1, 0.5f, 0.5f))), (std::vector<BodyID>{cA, cB}));
        // Points on faces and corners
        EXPECT_EQ(this->Point(Vec3(0, 0, 0)), std::vector<BodyID>{cA});
        EXPECT_EQ(this->Point(Vec3(2, 1, 1)), std::vector<BodyID>{cB});
        EXPECT_TRUE(this->Point(Vec3(2.0001f, 1, 1)).empty());
        // Spheres touching a face, and a corner (distance sqrt(3) from (-1,-1,-1) to the origin)
        EXPECT_EQ(this->Sphere(Vec3(-1, 0.5f, 0.5f), 1.0f), std::vector<BodyID>{cA});
        EXPECT_TRUE(this->Sphere(Vec3(-1, 0.5f, 0.5f), 0.999f).empty());
        EXPECT_EQ(this->Sphere(Vec3(-1, -1, -1), 1.7321f), std::vector<BodyID>{cA});
        EXPECT_TRUE(this->Sphere(Vec3(-1, -1, -1), 1.732f).empty());
        // Touching active bodies collide
        EXPECT_EQ(this->Pairs({cA, cB}), (std::vector<std::pair<BodyID, BodyID>>{{cA, cB}}));
        this->mBroadPhase->Update();
    }
}

TYPED_TEST(BroadPhaseCasesTest, RaysAlongAxesAndFaces)
{
    this->Add({{cA, cUnitBox, Layers::cStatic}, {cB, AABB(Vec3(3, 0, 0), Vec3(4, 1, 1)), Layers::cStatic}});
    for (int pass = 0; pass < 2; ++pass)
    {
        using Hits = std::vector<std::pair<BodyID, float>>;
        // Along +x through the middle of both faces: entry fractions 1/6 and 4/6
        EXPECT_EQ(this->Ray(Vec3(-1, 0.5f, 0.5f), Vec3(6, 0, 0)),
                  (Hits{{cA, 1.0f / 6.0f}, {cB, 4.0f / 6.0f}}));
        // Sliding along the top face plane (y = 1) and along an edge: closed slabs, still hits
        EXPECT_EQ(this->Ray(Vec3(-1, 1, 0.5f), Vec3(2, 0, 0)), (Hits{{cA, 0.5f}}));
        EXPECT_EQ(this->Ray(Vec3(-1, 1, 1), Vec3(2, 0, 0)), (Hits{{cA, 0.5f}}));
        // Parallel just above: miss
        EXPECT_TRUE(this->Ray(Vec3(-1, 1.001f, 0.5f), Vec3(10, 0, 0)).empty());
        // Ending exactly on the face: fraction 1; stopping short: miss
        EXPECT_EQ(this->Ray(Vec3(-1, 0.5f, 0.5f), Vec3(1, 0, 0)), (Hits{{cA, 1.0f}}));
        EXPECT_TRUE(this->Ray(Vec3(-1, 0.5f, 0.5f), Vec3(0.999f, 0, 0)).empty());
        // Down the -y axis into the top face; starting inside hits at 0
        EXPECT_EQ(this->Ray(Vec3(0.5f, 5, 0.5f), Vec3(0, -8, 0)), (Hits{{cA, 0.5f}}));
        EXPECT_EQ(this->Ray(Vec3(0.5f, 0.5f, 0.5f), Vec3(0, 0, 3)), (Hits{{cA, 0.0f}}));

        // A negative return stops after the first body; returning the fraction keeps only nearer bodies
        int visits = 0;
        this->mBroadPhase->CastRay({Vec3(-1, 0.5f, 0.5f), Vec3(6, 0, 0)}, {},
                                   [&](BodyID, float)
                                   {
                                       ++visits;
                                       return -1.0f;
                                   });
        EXPECT_EQ(visits, 1);
        float closest = 2.0f;
        this->mBroadPhase->CastRay({Vec3(-1, 0.5f, 0.5f), Vec3(6, 0, 0)}, {},
                                   [&](BodyID, float inFraction)
                                   {
                                       closest = std::min(closest, inFraction);
                                       return inFraction;
                                   });
        EXPECT_EQ(closest, 1.0f / 6.0f);

        // Swept box: a unit box centred at x = -5 moving 10 along +x first touches A when its max x reaches 0
        std::vector<std::pair<BodyID, float>> swept;
        this->mBroadPhase->CastAABox(AABB::FromCenterExtent(Vec3(-5, 0.5f, 0.5f), Vec3::Constant(0.5f)),
                                     Vec3(10, 0, 0), {},
                                     [&](BodyID inID, float inFraction)
                                     {
                                         swept.emplace_back(inID, inFraction);
                                         return 1.0f;
                                     });
        std::sort(swept.begin(), swept.end());
        ASSERT_EQ(swept.size(), 2u);
        EXPECT_EQ(swept[0].first, cA);
        EXPECT_NEAR(swept[0].second, 0.45f, 1.0e-6f);
        EXPECT_EQ(swept[1].first, cB);
        EXPECT_NEAR(swept[1].second, 0.75f, 1.0e-6f);
        // A swept box passing 1 mm above misses; one whose bottom face slides on the top face touches
        int sweptHits = 0;
        this->mBroadPhase->CastAABox(AABB::FromCenterExtent(Vec3(-5, 1.501f, 0.5f), Vec3::Constant(0.5f)),
                                     Vec3(10, 0, 0), {},
                                     [&](BodyID, float)
                                     {
                                         ++sweptHits;
                                         return 1.0f;
                                     });
        EXPECT_EQ(sweptHits, 0);
        this->mBroadPhase->CastAABox(AABB::FromCenterExtent(Vec3(-5, 1.5f, 0.5f), Vec3::Constant(0.5f)),
                                     Vec3(10, 0, 0), {},
                                     [&](BodyID, float)
                                     {
                                         ++sweptHits;
                                         return 1.0f;
                                     });
        EXPECT_EQ(sweptHits, 2);
        this->mBroadPhase->Update();
    }
}

TYPED_TEST(BroadPhaseCasesTest, LayerFilters)
{
    // Four overlapping bodies, one per object layer of the default setup
    this->Add({{cA, cUnitBox, Layers::cStatic},
               {cB, cUnitBox, Layers::cMoving},
               {cC, cUnitBox, Layers::cDebris},
               {cD, cUnitBox, Layers::cTrigger}});
    for (int pass = 0; pass < 2; ++pass)
    {
        EXPECT_EQ(this->Box(cUnitBox), (std::vector<BodyID>{cA, cB, cC, cD}));
        EXPECT_EQ(this->Box(cUnitBox, ObjectLayerMask(1) << Layers::cMoving), std::vector<BodyID>{cB});
        EXPECT_EQ(this->Box(cUnitBox, (ObjectLayerMask(1) << Layers::cStatic) |
                                          (ObjectLayerMask(1) << Layers::cTrigger)),
                  (std::vector<BodyID>{cA, cD}));
        EXPECT_TRUE(this->Box(cUnitBox, 0).empty());

        // Moving collides with static and moving; debris with static only; triggers with nothing
        using Pairs = std::vector<std::pair<BodyID, BodyID>>;
        EXPECT_EQ(this->Pairs({cB}), (Pairs{{cB, cA}}));
        EXPECT_EQ(this->Pairs({cC}), (Pairs{{cC, cA}}));
        EXPECT_TRUE(this->Pairs({cD}).empty());
        EXPECT_EQ(this->Pairs({cB, cC, cD}), (Pairs{{cB, cA}, {cC, cA}}));
        this->mBroadPhase->Update();
    }
}

TYPED_TEST(BroadPhaseCasesTest, PairsReportedOnce)
{
    // Three overlapping moving bodies and a static floor under them, a static body touching the floor
    const AABB floor(Vec3(-10, -1, -10), Vec3(10, 0, 10));
    this->Add({{cA, AABB(Vec3(0, 0, 0), Vec3(2, 2, 2)), Layers::cMoving},
               {cB, AABB(Vec3(1, 0, 1), Vec3(3, 2, 3)), Layers::cMoving},
               {cC, AABB(Vec3(1.5f, 0, 0), Vec3(2.5f, 1, 1)), Layers::cMoving},
               {cD, floor, Layers::cStatic},
               {BodyID(5, 1), AABB(Vec3(10, -1, 0), Vec3(11, 0, 1)), Layers::cStatic}});
    for (int pass = 0; pass < 2; ++pass)
    {
        using Pairs = std::vector<std::pair<BodyID, BodyID>>;
        // All three active: each active pair once as (lower index, higher index), plus each against the
        // floor; the two static bodies touch but neither is active. The absent id 77 is skipped.
        const Pairs all{{cA, cB}, {cA, cC}, {cA, cD}, {cB, cC}, {cB, cD}, {cC, cD}};
        EXPECT_EQ(this->Pairs({cC, BodyID(77, 1), cA, cB}), all);
        // Only B active: pairs with the inactive A and C are reported from B's side
        EXPECT_EQ(this->Pairs({cB}), (Pairs{{cB, cA}, {cB, cC}, {cB, cD}}));
        // A stale id of B (other sequence) is not B
        EXPECT_TRUE(this->Pairs({BodyID(2, 2)}).empty());
        this->mBroadPhase->Update();
    }
}

TYPED_TEST(BroadPhaseCasesTest, AbortLeavesNothingAdded)
{
    const std::vector<BroadPhaseBody> first{{cA, cUnitBox, Layers::cStatic}, {cB, cUnitBox, Layers::cMoving}};
    const std::vector<BroadPhaseBody> second{{cC, cUnitBox, Layers::cMoving}};
    BroadPhase::AddState firstState = this->mBroadPhase->AddBodiesPrepare(first);
    BroadPhase::AddState secondState = this->mBroadPhase->AddBodiesPrepare(second);
    // Prepared but not finalized: invisible
    EXPECT_TRUE(this->Box(cUnitBox).empty());
    this->mBroadPhase->AddBodiesAbort(firstState);
    this->mBroadPhase->AddBodiesFinalize(secondState);
    this->mBroadPhase->Update();
    EXPECT_EQ(this->mBroadPhase->GetBodyCount(), 1u);
    EXPECT_EQ(this->Box(cUnitBox), std::vector<BodyID>{cC});
    // The aborted ids can be added later
    this->Add({{cA, cUnitBox, Layers::cStatic}});
    EXPECT_EQ(this->Box(cUnitBox), (std::vector<BodyID>{cA, cC}));
}

TYPED_TEST(BroadPhaseCasesTest, ModificationsAreVisibleAtOnce)
{
    this->Add({{cA, cUnitBox, Layers::cMoving}});
    this->mBroadPhase->Update();
    const AABB far(Vec3(100, 0, 100), Vec3(101, 1, 101));
    // Move without Update: seen at the new place only
    const BroadPhaseBody moved{cA, far, Layers::cMoving};
    this->mBroadPhase->NotifyBodiesAABBChanged({&moved, 1});
    EXPECT_TRUE(this->Box(cUnitBox).empty());
    EXPECT_EQ(this->Box(far), std::vector<BodyID>{cA});
    // A small move stays findable too
    const BroadPhaseBody nudged{cA, AABB(far.mMin + Vec3(0.1f, 0, 0), far.mMax + Vec3(0.1f, 0, 0)),
                                Layers::cMoving};
    this->mBroadPhase->Update();
    this->mBroadPhase->NotifyBodiesAABBChanged({&nudged, 1});
    EXPECT_EQ(this->Point(Vec3(101.05f, 0.5f, 100.5f)), std::vector<BodyID>{cA});
    EXPECT_TRUE(this->Point(Vec3(100.05f, 0.5f, 100.5f)).empty());
    // A layer change to static moves it to the other broad-phase layer
    const BroadPhaseBody asStatic{cA, far, Layers::cStatic};
    this->mBroadPhase->NotifyBodiesAABBChanged({&asStatic, 1});
    EXPECT_EQ(this->Box(far, ObjectLayerMask(1) << Layers::cStatic), std::vector<BodyID>{cA});
    EXPECT_TRUE(this->Box(far, ObjectLayerMask(1) << Layers::cMoving).empty());
    // Remove without Update: gone
    this->mBroadPhase->RemoveBodies({&cA, 1});
    EXPECT_TRUE(this->Box(far).empty());
    EXPECT_EQ(this->mBroadPhase->GetBodyCount(), 0u);
}

TYPED_TEST(BroadPhaseCasesTest, BadInputIsIgnored)
{
    this->Add({{cA, cUnitBox, Layers::cMoving}});
    this->mBroadPhase->Update();

    // Adding the same index again (same or other sequence) keeps the first add
    const AABB far(Vec3(50, 0, 50), Vec3(51, 1, 51));
    this->Add({{cA, far, Layers::cMoving}, {BodyID(1, 9), far, Layers::cMoving}});
    EXPECT_EQ(this->mBroadPhase->GetBodyCount(), 1u);
    EXPECT_EQ(this->Box(cUnitBox), std::vector<BodyID>{cA});
    EXPECT_TRUE(this->Box(far).empty());

    // Removing or moving an absent or stale id does nothing
    const BodyID absent[] = {cB, BodyID(1, 2)};
    this->mBroadPhase->RemoveBodies(absent);
    const BroadPhaseBody staleMove{BodyID(1, 2), far, Layers::cMoving};
    this->mBroadPhase->NotifyBodiesAABBChanged({&staleMove, 1});
    EXPECT_EQ(this->mBroadPhase->GetBodyCount(), 1u);
    EXPECT_EQ(this->Box(cUnitBox), std::vector<BodyID>{cA});

    // Non-finite or inverted bounds: assert in debug, ignored in release (the old bounds stay)
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const BroadPhaseBody nanBody{cB, AABB(Vec3(nan, 0, 0), Vec3(1, 1, 1)), Layers::cMoving};
    const BroadPhaseBody infMove{cA, AABB(Vec3(0, 0, 0), Vec3(inf, 1, 1)), Layers::cMoving};
    const BroadPhaseBody invertedMove{cA, AABB(Vec3(1, 0, 0), Vec3(0, 1, 1)), Layers::cMoving};
    EXPECT_DEBUG_DEATH(this->Add({nanBody}), "");
    EXPECT_DEBUG_DEATH(this->mBroadPhase->NotifyBodiesAABBChanged({&infMove, 1}), "");
    EXPECT_DEBUG_DEATH(this->mBroadPhase->NotifyBodiesAABBChanged({&invertedMove, 1}), "");
    EXPECT_EQ(this->mBroadPhase->GetBodyCount(), 1u);
    EXPECT_EQ(this->Box(cUnitBox), std::vector<BodyID>{cA});
    EXPECT_EQ(this->Point(Vec3(0.5f, 0.5f, 0.5f)), std::vector<BodyID>{cA});
}

} // namespace
} // namespace cairn
