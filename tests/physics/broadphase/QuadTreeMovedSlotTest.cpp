// A rebuild grows the slots of the bodies that had moved by a margin (BroadPhaseQuadTree::cMovedSlotMargin)
// and stretches them ahead of their motion (cMovedSlotReach): their next small moves, and the next few steps
// of a steady fall, write no node, so the tree is unchanged and the next update rebuilds nothing. Queries
// must still report exactly the bodies whose own bounds match, not their grown slots.

#include "broadphase/BroadPhaseBruteForce.h"
#include "broadphase/BroadPhaseQuadTree.h"
#include "broadphase/QuadTree.h"
#include "common/TestRandom.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

std::vector<BodyID> BoxQuery(const BroadPhase& inBroadPhase, const AABB& inBox)
{
    std::vector<BodyID> hits;
    inBroadPhase.CollideAABox(inBox, {}, [&](BodyID inID) { hits.push_back(inID); });
    std::sort(hits.begin(), hits.end());
    return hits;
}

AABB Shifted(const AABB& inBox, const Vec3& inDelta)
{
    return AABB(inBox.mMin + inDelta, inBox.mMax + inDelta);
}

/// inCount bodies of inSize (m, 0.8 unless given) in a 60 m x 60 m field, added to both broad phases; the
/// tested one updated.
std::vector<BroadPhaseBody> AddField(uint32_t inCount, test::TestRandom& ioRandom,
                                     BroadPhaseQuadTree& ioTested, BroadPhaseBruteForce& ioReference,
                                     float inSize = 0.8f)
{
    std::vector<BroadPhaseBody> bodies;
    for (uint32_t i = 0; i < inCount; ++i)
    {
        const Vec3 centre(ioRandom.Uniform(0.0f, 60.0f), ioRandom.Uniform(0.0f, 4.0f),
                          ioRandom.Uniform(0.0f, 60.0f));
        bodies.push_back(
            {BodyID(i, 1), AABB::FromCenterExtent(centre, Vec3::Constant(0.5f * inSize)), Layers::cMoving});
    }
    for (BroadPhase* broadPhase :
         {static_cast<BroadPhase*>(&ioTested), static_cast<BroadPhase*>(&ioReference)})
        broadPhase->AddBodiesFinalize(broadPhase->AddBodiesPrepare(bodies));
    ioTested.Update();
    return bodies;
}

TEST(QuadTreeMovedSlotTest, SmallMovesAfterARebuildChangeNoNodeAndQueriesStayExact)
{
    static_assert(BroadPhaseQuadTree::cMovedSlotMargin >= 0.02f, "the jiggles below must fit in the margin");
    test::TestRandom random(3);
    BroadPhaseQuadTree tested(2000, LayerSetup::CreateDefault());
    BroadPhaseBruteForce reference;
    std::vector<BroadPhaseBody> moving = AddField(2000, random, tested, reference);
    auto moveAll = [&](float inStep)
    {
        for (BroadPhaseBody& body : moving)
            body.mBounds =
                Shifted(body.mBounds, Vec3(random.Uniform(-inStep, inStep), random.Uniform(-inStep, inStep),
                                           random.Uniform(-inStep, inStep)));
        tested.NotifyBodiesAABBChanged(moving);
        reference.NotifyBodiesAABBChanged(moving);
    };
    // Queries around each body, a little wider than it (inside its grown slot) and touching it from outside
    auto expectExactQueries = [&](const char* inWhen)
    {
        for (size_t i = 0; i < moving.size(); i += 7)
            for (const float grow : {-0.1f, 0.0f, 0.01f, 0.03f})
            {
                const AABB box = moving[i].mBounds.Expanded(grow);
                ASSERT_EQ(BoxQuery(tested, box), BoxQuery(reference, box)) << inWhen << ", body " << i;
            }
    };

    moveAll(0.3f); // A real move: the slots grow, the nodes change
    tested.Update();
    EXPECT_GT(tested.GetLastUpdateStats().mLayersRebuilt, 0u)
        << "the moved bodies were rebuilt into grown slots";
    expectExactQueries("after the rebuild");
    for (int frame = 0; frame < 3; ++frame)
    {
        // 1 cm jiggles a frame, less than the margin in all: no slot grows
        moveAll(0.01f / 3.0f);
        expectExactQueries("after a jiggle");
        tested.Update();
        EXPECT_EQ(tested.GetLastUpdateStats().mLayersRebuilt, 0u) << "frame " << frame << ": no node changed";
        expectExactQueries("after an update with nothing to rebuild");
    }
    moveAll(0.3f); // Out of the grown slots again
    expectExactQueries("after a move out of the slots");
    tested.Update();
    EXPECT_GT(tested.GetLastUpdateStats().mLayersRebuilt, 0u);
    expectExactQueries("after the second rebuild");
    EXPECT_TRUE(tested.Validate());
}

// A small body's margin is a share of its size (QuadTree::cMovedSlotMarginShare): 3 cm moves stay inside the
// slots of 0.8 m bodies (a 5 cm margin), and take 8 cm bodies (a margin of 1.2 cm) out of theirs
TEST(QuadTreeMovedSlotTest, ASmallBodysSlotMarginIsAShareOfItsSize)
{
    static_assert(BroadPhaseQuadTree::cMovedSlotMargin >= 0.04f,
                  "3 cm moves must fit in a large body's margin");
    for (const float size : {0.8f, 0.08f})
    {
        SCOPED_TRACE(size);
        static_assert(QuadTree::cMovedSlotMarginShare * 0.08f < 0.02f,
                      "a small body's margin must be under 2 cm");
        test::TestRandom random(5);
        BroadPhaseQuadTree tested(2000, LayerSetup::CreateDefault());
        BroadPhaseBruteForce reference;
        std::vector<BroadPhaseBody> moving = AddField(2000, random, tested, reference, size);
        auto moveAll = [&](float inStep)
        {
            for (BroadPhaseBody& body : moving)
                body.mBounds = Shifted(body.mBounds,
                                       Vec3(random.Uniform(-inStep, inStep), random.Uniform(-inStep, inStep),
                                            random.Uniform(-inStep, inStep)));
            tested.NotifyBodiesAABBChanged(moving);
            reference.NotifyBodiesAABBChanged(moving);
            for (size_t i = 0; i < moving.size(); i += 7)
                for (const float grow : {0.0f, 0.01f, 0.03f})
                {
                    const AABB box = moving[i].mBounds.Expanded(grow);
                    ASSERT_EQ(BoxQuery(tested, box), BoxQuery(reference, box)) << "body " << i;
                }
        };
        moveAll(0.3f); // A real move: the moved slots are made
        tested.Update();
        ASSERT_GT(tested.GetLastUpdateStats().mLayersRebuilt, 0u);
        moveAll(0.03f);
        tested.Update();
        if (size > 0.5f)
            EXPECT_EQ(tested.GetLastUpdateStats().mLayersRebuilt, 0u) << "3 cm moves left a 5 cm margin";
        else
            EXPECT_GT(tested.GetLastUpdateStats().mLayersRebuilt, 0u)
                << "3 cm moves stayed in a 1.2 cm margin";
        EXPECT_TRUE(tested.Validate());
    }
}

/// Moves every body by inDelta in both broad phases and checks queries around some of them.
void MoveAllAndCheck(std::vector<BroadPhaseBody>& ioBodies, const Vec3& inDelta, BroadPhaseQuadTree& ioTested,
                     BroadPhaseBruteForce& ioReference)
{
    for (BroadPhaseBody& body : ioBodies)
        body.mBounds = Shifted(body.mBounds, inDelta);
    ioTested.NotifyBodiesAABBChanged(ioBodies);
    ioReference.NotifyBodiesAABBChanged(ioBodies);
    for (size_t i = 0; i < ioBodies.size(); i += 13)
        for (const float grow : {-0.1f, 0.0f, 0.2f})
        {
            const AABB box = ioBodies[i].mBounds.Expanded(grow);
            ASSERT_EQ(BoxQuery(ioTested, box), BoxQuery(ioReference, box)) << "body " << i;
        }
}

TEST(QuadTreeMovedSlotTest, SteadyFallIsRebuiltIntoSlotsStretchedAheadAndQueriesStayExact)
{
    static_assert(BroadPhaseQuadTree::cMovedSlotReach >= 2.0f, "the count below assumes slots reach 2 moves");
    BroadPhaseQuadTree tested(1000, LayerSetup::CreateDefault());
    BroadPhaseBruteForce reference;
    test::TestRandom random(5);
    std::vector<BroadPhaseBody> bodies = AddField(1000, random, tested, reference);
    // 10 cm a frame straight down: each rebuild stretches the slots below by twice the fall since the last
    // one past the margin, so the falls between rebuilds lengthen (2, 5, then 11 frames at the 1 m cap).
    // Exact slots would rebuild every frame; the margin alone (5 cm) too
    constexpr int cFrames = 30;
    int rebuilds = 0;
    for (int frame = 0; frame < cFrames; ++frame)
    {
        MoveAllAndCheck(bodies, Vec3(0.0f, -0.1f, 0.0f), tested, reference);
        tested.Update();
        rebuilds += tested.GetLastUpdateStats().mLayersRebuilt > 0 ? 1 : 0;
        ASSERT_TRUE(tested.Validate()) << "frame " << frame;
    }
    EXPECT_GE(rebuilds, 3) << "the falling bodies left their slots now and then";
    EXPECT_LE(rebuilds, cFrames / 3) << "the slots reached ahead of the fall";
}

TEST(QuadTreeMovedSlotTest, BodiesThatStopGiveBackTheStretchAtTheNextRebuilds)
{
    BroadPhaseQuadTree tested(1000, LayerSetup::CreateDefault());
    BroadPhaseBruteForce reference;
    test::TestRandom random(5);
    std::vector<BroadPhaseBody> bodies = AddField(1000, random, tested, reference);
    MoveAllAndCheck(bodies, Vec3(0.0f, -0.3f, 0.0f), tested, reference);
    tested.Update(); // The slots stretch 0.5 m below (twice the 0.25 m past the margin)
    // At rest, as an awake body is: notified every frame with the same bounds (its slot stays loose). Each
    // full rebuild must see no move, not take the stretch the body did not use for room left behind (that
    // would stretch the slot the other way, and back, up to the cap)
    for (int rebuild = 0; rebuild < 3; ++rebuild)
    {
        MoveAllAndCheck(bodies, Vec3::Zero(), tested, reference);
        tested.RebuildAll();
    }
    // Back to the margin on every side: a 10 cm move either way leaves the slots
    for (const float dy : {0.1f, -0.1f})
    {
        MoveAllAndCheck(bodies, Vec3::Zero(), tested, reference);
        tested.RebuildAll();
        MoveAllAndCheck(bodies, Vec3(0.0f, dy, 0.0f), tested, reference);
        tested.Update();
        EXPECT_GT(tested.GetLastUpdateStats().mLayersRebuilt, 0u) << "a move of " << dy << " m stayed inside";
        MoveAllAndCheck(bodies, Vec3(0.0f, -dy, 0.0f), tested, reference); // Back where they rested
    }
    EXPECT_TRUE(tested.Validate());
}

} // namespace
} // namespace cairn
