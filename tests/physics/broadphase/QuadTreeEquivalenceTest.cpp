// QuadTree against the brute-force oracle on random worlds. The quad tree's bounds only grow until a rebuild,
// so after every step of a random sequence of add batches, aborted batches, removes and moves:
//  - it must report exactly what brute force reports when fed each body's union of all bounds since its add
//    (sorted vectors compared element by element, ray fractions included), and
//  - it must report everything brute force reports for the bodies' true current bounds.

#include "cairn/physics/broadphase/BroadPhaseBruteForce.h"
#include "cairn/physics/broadphase/QuadTree.h"
#include "common/TestRandom.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <random>
#include <utility>
#include <vector>

namespace cairn
{
namespace
{

constexpr uint32_t cNumBodies = 5000;

/// Random worlds in a 250 m x 60 m x 250 m box (see TestRandom for the grid snapping).
class World : public test::TestRandom
{
public:
    using TestRandom::TestRandom;

    Vec3 Point() { return Vec3(Coordinate(-125, 125), Coordinate(-30, 30), Coordinate(-125, 125)); }
    AABB Box()
    {
        const Vec3 p = Point();
        const Vec3 e(Coordinate(0, 4), Coordinate(0, 4), Coordinate(0, 4));
        return AABB(p - e, p + e);
    }
};

template <class Query> std::vector<BodyID> Collect(Query&& inQuery)
{
    std::vector<BodyID> ids;
    inQuery([&](BodyID inID) { ids.push_back(inID); });
    std::sort(ids.begin(), ids.end());
    return ids;
}

std::vector<std::pair<BodyID, float>> CollectRay(const auto& inBroadPhase, const RayCast& inRay)
{
    std::vector<std::pair<BodyID, float>> hits;
    inBroadPhase.CastRay(inRay, {},
                         [&](BodyID inID, float inFraction)
                         {
                             hits.emplace_back(inID, inFraction);
                             return 1.0f;
                         });
    std::sort(hits.begin(), hits.end());
    return hits;
}

float ClosestRay(const auto& inBroadPhase, const RayCast& inRay)
{
    float closest = 2.0f;
    inBroadPhase.CastRay(inRay, {},
                         [&](BodyID, float inFraction)
                         {
                             closest = std::min(closest, inFraction);
                             return closest;
                         });
    return closest;
}

bool IsSubset(const std::vector<BodyID>& inSmall, const std::vector<BodyID>& inLarge)
{
    return std::includes(inLarge.begin(), inLarge.end(), inSmall.begin(), inSmall.end());
}

class QuadTreeEquivalence : public ::testing::TestWithParam<uint32_t>
{
};

TEST_P(QuadTreeEquivalence, MatchesBruteForceWithGrownBounds)
{
    World world(GetParam());
    QuadTree tree(cNumBodies, 100000);
    BroadPhaseBruteForce exact; // True current bounds
    BroadPhaseBruteForce grown; // Union of all bounds since the add: what the tree must store exactly

    std::vector<uint32_t> sequence(cNumBodies, 0);
    std::vector<AABB> grownBounds(cNumBodies), currentBounds(cNumBodies);
    std::vector<ObjectLayer> layers(cNumBodies, 0);
    std::vector<uint32_t> present, absent;
    for (uint32_t i = 0; i < cNumBodies; ++i)
        absent.push_back(i);

    auto takeRandom = [&](std::vector<uint32_t>& ioFrom)
    {
        const uint32_t k = world.Index(uint32_t(ioFrom.size()));
        const uint32_t v = ioFrom[k];
        ioFrom[k] = ioFrom.back();
        ioFrom.pop_back();
        return v;
    };

    size_t totalBoxHits = 0, totalPointHits = 0; // The queries must not be trivially empty
    for (int step = 0; step < 150; ++step)
    {
        const float op = world.Uniform(0, 1);
        if (op < 0.4f && !absent.empty())
        {
            // Add a batch (sometimes a single body, sometimes one with all centres equal, sometimes aborted)
            const uint32_t count =
                std::min<uint32_t>(uint32_t(absent.size()), world.Chance(0.2f) ? 1 : 1 + world.Index(400));
            const bool sameCentre = world.Chance(0.1f);
            const Vec3 centre = world.Point();
            std::vector<BroadPhaseBody> batch;
            for (uint32_t i = 0; i < count; ++i)
            {
                const uint32_t index = takeRandom(absent);
                AABB box = world.Box();
                if (sameCentre) box = AABB::FromCenterExtent(centre, box.HalfExtent());
                batch.push_back({BodyID(index, ++sequence[index]), box, ObjectLayer(world.Index(4))});
            }
            const uint32_t nodesBefore = tree.GetNumAllocatedNodes();
            QuadTree::SubTree sub = tree.BuildSubTree(batch);
            ASSERT_NE(sub.mChild, QuadTree::cInvalidChild);
            if (world.Chance(0.15f))
            {
                tree.FreeSubTree(sub);
                EXPECT_EQ(tree.GetNumAllocatedNodes(), nodesBefore);
                for (const BroadPhaseBody& body : batch)
                {
                    EXPECT_FALSE(tree.Contains(body.mID));
                    absent.push_back(body.mID.GetIndex());
                }
            }
            else
            {
                ASSERT_TRUE(tree.LinkSubTree(sub));
                exact.AddBodiesFinalize(exact.AddBodiesPrepare(batch));
                grown.AddBodiesFinalize(grown.AddBodiesPrepare(batch));
                for (const BroadPhaseBody& body : batch)
                {
                    grownBounds[body.mID.GetIndex()] = body.mBounds;
                    currentBounds[body.mID.GetIndex()] = body.mBounds;
                    layers[body.mID.GetIndex()] = body.mLayer;
                    present.push_back(body.mID.GetIndex());
                }
            }
        }
        else if (op < 0.6f && !present.empty())
        {
            const uint32_t count = std::min<uint32_t>(uint32_t(present.size()), 1 + world.Index(100));
            std::vector<BodyID> removed;
            for (uint32_t i = 0; i < count; ++i)
            {
                const uint32_t index = takeRandom(present);
                removed.push_back(BodyID(index, sequence[index]));
                absent.push_back(index);
            }
            for (BodyID id : removed)
            {
                tree.RemoveBody(id);
                EXPECT_FALSE(tree.Contains(id));
            }
            exact.RemoveBodies(removed);
            grown.RemoveBodies(removed);
        }
        else if (!present.empty())
        {
            const uint32_t count = std::min<uint32_t>(uint32_t(present.size()), 1 + world.Index(300));
            std::vector<BroadPhaseBody> moved, movedGrown;
            for (uint32_t i = 0; i < count; ++i)
            {
                const uint32_t index = present[world.Index(uint32_t(present.size()))];
                const BodyID id(index, sequence[index]);
                AABB box = world.Box();
                if (world.Chance(0.7f)) // Small move near the old place
                {
                    const Vec3 offset(world.Uniform(-1, 1), world.Uniform(-1, 1), world.Uniform(-1, 1));
                    box = AABB::FromCenterExtent(currentBounds[index].Center() + offset, box.HalfExtent());
                }
                tree.MoveBody(id, box);
                currentBounds[index] = box;
                grownBounds[index].Encapsulate(box);
                // The tree keeps the add-time layer: give the oracles the same one
                moved.push_back({id, box, layers[index]});
                movedGrown.push_back({id, grownBounds[index], layers[index]});
            }
            exact.NotifyBodiesAABBChanged(moved);
            grown.NotifyBodiesAABBChanged(movedGrown);
        }

        ASSERT_EQ(grown.GetBodyCount(), present.size());
        for (uint32_t index : present)
        {
            const AABB b = tree.GetBodyBounds(BodyID(index, sequence[index]));
            ASSERT_TRUE(b.mMin == grownBounds[index].mMin && b.mMax == grownBounds[index].mMax) << index;
        }

        for (int q = 0; q < 20; ++q)
        {
            BroadPhaseQueryFilter filter;
            if (world.Chance(0.3f)) filter.mObjectLayers = ObjectLayerMask(world.Index(16));

            AABB box = world.Box();
            if (world.Chance(0.3f)) box = box.Expanded(world.Uniform(0, 30));
            const auto treeBox = Collect([&](auto v) { tree.CollideAABox(box, filter, v); });
            ASSERT_EQ(treeBox, Collect([&](auto v) { grown.CollideAABox(box, filter, v); }));
            ASSERT_TRUE(IsSubset(Collect([&](auto v) { exact.CollideAABox(box, filter, v); }), treeBox));

            totalBoxHits += treeBox.size();
            const Vec3 point = world.Point();
            const auto treePoint = Collect([&](auto v) { tree.CollidePoint(point, filter, v); });
            ASSERT_EQ(treePoint, Collect([&](auto v) { grown.CollidePoint(point, filter, v); }));
            ASSERT_TRUE(IsSubset(Collect([&](auto v) { exact.CollidePoint(point, filter, v); }), treePoint));

            totalPointHits += treePoint.size();
            const float radius = world.Uniform(0, 10);
            ASSERT_EQ(Collect([&](auto v) { tree.CollideSphere(point, radius, filter, v); }),
                      Collect([&](auto v) { grown.CollideSphere(point, radius, filter, v); }));

            RayCast ray;
            ray.mOrigin = world.Point();
            ray.mDirection = world.Point() - ray.mOrigin;
            if (world.Chance(0.3f)) ray.mDirection[world.Index(3)] = 0.0f; // Axis-parallel components
            ASSERT_EQ(CollectRay(tree, ray), CollectRay(grown, ray));
            ASSERT_EQ(ClosestRay(tree, ray), ClosestRay(grown, ray));
        }
    }
    EXPECT_GT(totalBoxHits, 1000u);
    EXPECT_GT(totalPointHits, 10u);
}

INSTANTIATE_TEST_SUITE_P(Seeds, QuadTreeEquivalence, ::testing::Values(1u, 2u, 3u));

TEST(QuadTree, InvalidInputIgnored)
{
    QuadTree tree(16, 64);
    std::vector<BroadPhaseBody> batch = {{BodyID(3, 1), AABB(Vec3::Zero(), Vec3::Ones()), 0}};
    const QuadTree::SubTree sub = tree.BuildSubTree(batch);
    ASSERT_TRUE(tree.LinkSubTree(sub));
    tree.MoveBody(BodyID(3, 2), AABB(Vec3::Constant(5), Vec3::Constant(6))); // Stale sequence: ignored
    tree.RemoveBody(BodyID(3, 2));                                           // Ignored
    tree.RemoveBody(BodyID(7, 1));                                           // Not present: ignored
    EXPECT_TRUE(tree.Contains(BodyID(3, 1)));
    const auto hits = Collect([&](auto v) { tree.CollidePoint(Vec3::Constant(0.5f), {}, v); });
    ASSERT_EQ(hits, std::vector<BodyID>{BodyID(3, 1)});
    EXPECT_TRUE(Collect([&](auto v) { tree.CollidePoint(Vec3::Constant(5.5f), {}, v); }).empty());
}

TEST(QuadTree, NodePoolExhaustionFailsCleanly)
{
    QuadTree tree(1000, 8); // Root + 7 nodes
    std::vector<BroadPhaseBody> batch;
    for (uint32_t i = 0; i < 1000; ++i)
        batch.push_back(
            {BodyID(i, 1), AABB::FromCenterExtent(Vec3(float(i), 0, 0), Vec3::Constant(0.25f)), 0});
    const uint32_t before = tree.GetNumAllocatedNodes();
    const QuadTree::SubTree sub = tree.BuildSubTree(batch);
    EXPECT_EQ(sub.mChild, QuadTree::cInvalidChild);
    EXPECT_EQ(tree.GetNumAllocatedNodes(), before);
    EXPECT_FALSE(tree.Contains(BodyID(0, 1)));
}

} // namespace
} // namespace cairn
