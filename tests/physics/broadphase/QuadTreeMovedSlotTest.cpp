// A rebuild grows the slots of the bodies that had moved by a margin (BroadPhaseQuadTree::cMovedSlotMargin):
// their next small moves write no node, so the tree is unchanged and the next update rebuilds nothing.
// Queries must still report exactly the bodies whose own bounds match, not their grown slots.

#include "cairn/physics/broadphase/BroadPhaseBruteForce.h"
#include "cairn/physics/broadphase/BroadPhaseQuadTree.h"
#include "common/TestRandom.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <vector>

namespace cairn
{
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

TEST(QuadTreeMovedSlotTest, SmallMovesAfterARebuildChangeNoNodeAndQueriesStayExact)
{
    static_assert(BroadPhaseQuadTree::cMovedSlotMargin >= 0.02f, "the jiggles below must fit in the margin");
    test::TestRandom random(3);
    std::vector<BroadPhaseBody> moving;
    for (uint32_t i = 0; i < 2000; ++i)
    {
        const Vec3 centre(random.Uniform(0.0f, 60.0f), random.Uniform(0.0f, 4.0f),
                          random.Uniform(0.0f, 60.0f));
        moving.push_back(
            {BodyID(i, 1), AABB::FromCenterExtent(centre, Vec3::Constant(0.4f)), Layers::cMoving});
    }
    BroadPhaseQuadTree tested(2000, LayerSetup::CreateDefault());
    BroadPhaseBruteForce reference;
    for (BroadPhase* broadPhase : {static_cast<BroadPhase*>(&tested), static_cast<BroadPhase*>(&reference)})
        broadPhase->AddBodiesFinalize(broadPhase->AddBodiesPrepare(moving));
    tested.Update();
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

} // namespace
} // namespace cairn
