// The quad-tree broad phase's static candidate cache (PairCandidateCache): FindCollidingPairs serves an
// active body's pairs with the trees that did not change since its last call from the bodies it remembered
// near the body. Whatever happens between two calls (statics added, moved, removed or put in another object
// layer, another collision table, an active list in another order, an index reused, more candidates than an
// entry keeps, a full table, a body listed twice), the pairs must be exactly the brute-force reference's; and
// the cache must really serve the queries of resting bodies, else these tests would prove nothing.

#include "broadphase/BroadPhaseBruteForce.h"
#include "broadphase/BroadPhaseQuadTree.h"

#include <algorithm>
#include <atomic>
#include <gtest/gtest.h>
#include <mutex>
#include <random>
#include <span>
#include <thread>
#include <utility>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

using PairList = std::vector<std::pair<BodyID, BodyID>>;

/// A quad-tree broad phase and the brute-force reference fed the same operations.
class Worlds
{
public:
    explicit Worlds(const LayerSetup& inLayers = LayerSetup::CreateDefault(), uint32_t inMaxBodies = 20000)
        : mLayers(inLayers), mTested(inMaxBodies, inLayers)
    {
    }

    void Add(const std::vector<BroadPhaseBody>& inBodies)
    {
        for (BroadPhase* broadPhase :
             {static_cast<BroadPhase*>(&mTested), static_cast<BroadPhase*>(&mOracle)})
            broadPhase->AddBodiesFinalize(broadPhase->AddBodiesPrepare(inBodies));
    }
    void Move(const std::vector<BroadPhaseBody>& inBodies)
    {
        mTested.NotifyBodiesAABBChanged(inBodies);
        mOracle.NotifyBodiesAABBChanged(inBodies);
    }
    void Remove(const std::vector<BodyID>& inBodies)
    {
        mTested.RemoveBodies(inBodies);
        mOracle.RemoveBodies(inBodies);
    }

    /// The pairs of both, sorted; inThreads > 1 splits the active list over that many threads.
    static PairList Pairs(const BroadPhase& inBroadPhase, std::span<const BodyID> inActive,
                          const LayerSetup& inLayers, uint32_t inThreads = 1)
    {
        auto runRanges = [&](uint32_t inCount, FunctionRef<void(uint32_t, uint32_t)> inBody)
        {
            std::vector<std::thread> threads;
            for (uint32_t t = 0; t < inThreads; ++t)
                threads.emplace_back([&, t]
                                     { inBody(inCount * t / inThreads, inCount * (t + 1) / inThreads); });
            for (std::thread& thread : threads)
                thread.join();
        };
        const ParallelRanges ranges = runRanges; // Named above: a FunctionRef does not own its callable
        PairList pairs;
        std::mutex mutex;
        inBroadPhase.FindCollidingPairs(
            inActive, inLayers,
            [&](BodyID inA, BodyID inB)
            {
                const std::lock_guard lock(mutex);
                pairs.emplace_back(inA, inB);
            },
            inThreads > 1 ? &ranges : nullptr);
        std::sort(pairs.begin(), pairs.end());
        return pairs;
    }

    /// Compares the two on inActive; returns the number of pairs (so a test can see it is not empty).
    size_t ExpectSamePairs(std::span<const BodyID> inActive, const char* inWhen, uint32_t inThreads = 1,
                           const LayerSetup* inLayers = nullptr)
    {
        const LayerSetup& layers = inLayers != nullptr ? *inLayers : mLayers;
        const PairList expected = Pairs(mOracle, inActive, layers);
        const PairList found = Pairs(mTested, inActive, layers, inThreads);
        EXPECT_EQ(found, expected) << inWhen;
        return expected.size();
    }

    BroadPhaseQuadTree& Tested() { return mTested; }

private:
    LayerSetup mLayers;
    BroadPhaseQuadTree mTested;
    BroadPhaseBruteForce mOracle;
};

AABB Box(const Vec3& inCenter, float inHalfExtent)
{
    return AABB::FromCenterExtent(inCenter, Vec3::Constant(inHalfExtent));
}

/// A floor of static tiles (1 m apart, 0.9 m wide) and boxes resting on it, each over a different tile, and
/// far away enough statics for the static tree to be served from the cache (cMinCachedTreeBodies).
struct RestingScene
{
    std::vector<BroadPhaseBody> mStatics, mMoving;
    std::vector<BodyID> mActive;

    RestingScene(uint32_t inSide, uint32_t inEvery)
    {
        uint32_t index = 0;
        for (uint32_t x = 0; x < inSide; ++x)
            for (uint32_t z = 0; z < inSide; ++z)
                mStatics.push_back(
                    {BodyID(index++, 1), Box(Vec3(float(x), -0.45f, float(z)), 0.45f), Layers::cStatic});
        for (uint32_t i = 0; i < BroadPhaseQuadTree::cMinCachedTreeBodies; ++i)
            mStatics.push_back(
                {BodyID(index++, 1), Box(Vec3(1000.0f + float(i), 0.0f, 0.0f), 0.4f), Layers::cStatic});
        for (uint32_t x = 0; x < inSide; x += inEvery)
            for (uint32_t z = 0; z < inSide; z += inEvery)
            {
                // Resting on the tile, touching it: a pair
                mMoving.push_back(
                    {BodyID(index++, 1), Box(Vec3(float(x), 0.2f, float(z)), 0.2f), Layers::cMoving});
                mActive.push_back(mMoving.back().mID);
            }
    }

    /// Slides every resting box by a few millimetres (as contacts jiggle bodies), staying in its grown box
    /// and on its tile.
    std::vector<BroadPhaseBody> Jiggle(std::mt19937& ioRandom)
    {
        std::uniform_real_distribution<float> delta(-0.004f, 0.004f);
        for (BroadPhaseBody& body : mMoving)
        {
            const Vec3 d(delta(ioRandom), 0.0f, delta(ioRandom));
            body.mBounds = AABB(body.mBounds.mMin + d, body.mBounds.mMax + d);
        }
        return mMoving;
    }
};

uint64_t Queries(const BroadPhaseQuadTree::CandidateCacheStats& inStats)
{
    return inStats.mReused + inStats.mWalked + inStats.mRefilled + inStats.mUncached;
}

TEST(BroadPhaseCandidateCacheTest, RestingBodiesReuseTheirCandidatesWithTheSamePairs)
{
    for (const float margin : {BroadPhaseQuadTree::cDefaultCandidateCacheMargin, 0.0f})
    {
        Worlds worlds;
        worlds.Tested().SetCandidateCacheMargin(margin);
        RestingScene scene(60, 3);
        worlds.Add(scene.mStatics);
        worlds.Add(scene.mMoving);
        std::mt19937 random(5);
        size_t pairs = 0;
        for (int call = 0; call < 40; ++call)
        {
            worlds.Move(scene.Jiggle(random)); // The moving tree changes every call, the static one never
            worlds.Tested().Update();
            pairs += worlds.ExpectSamePairs(scene.mActive, "a resting call", call % 2 == 0 ? 1 : 3);
        }
        EXPECT_EQ(pairs, 40 * scene.mActive.size()) << "every box touches its tile, and only it";
        const BroadPhaseQuadTree::CandidateCacheStats stats = worlds.Tested().GetCandidateCacheStats();
        if (margin > 0)
        {
            // The first call walks the static tree (it changed since the last call: it was built); the second
            // fills every entry; the jiggles stay inside 0.25 m for the remaining 38
            EXPECT_EQ(stats.mRefilled, scene.mActive.size());
            EXPECT_EQ(stats.mReused, 38 * scene.mActive.size());
            EXPECT_EQ(Queries(stats), 39 * scene.mActive.size());
        }
        else
            EXPECT_EQ(Queries(stats), 0u) << "margin 0 turns the cache off";
    }
}

TEST(BroadPhaseCandidateCacheTest, SmallTreesAreAlwaysWalked)
{
    // The resting scene without its far statics: 900 tiles, under cMinCachedTreeBodies
    Worlds worlds;
    RestingScene scene(30, 3);
    scene.mStatics.resize(30 * 30);
    static_assert(30 * 30 < BroadPhaseQuadTree::cMinCachedTreeBodies);
    worlds.Add(scene.mStatics);
    worlds.Add(scene.mMoving);
    for (int call = 0; call < 4; ++call)
        EXPECT_EQ(worlds.ExpectSamePairs(scene.mActive, "a small static tree"), scene.mActive.size());
    EXPECT_EQ(Queries(worlds.Tested().GetCandidateCacheStats()), 0u);
}

TEST(BroadPhaseCandidateCacheTest, BodiesLeavingTheirGrownBoxAreWalkedAgain)
{
    Worlds worlds;
    RestingScene scene(30, 3);
    worlds.Add(scene.mStatics);
    worlds.Add(scene.mMoving);
    // Every box slides 0.1 m a call along x over the tiles: out of its 0.25 m grown box after the third call,
    // then out of boxes that also reach as far ahead as it moved (at most 1 m) every few calls
    for (int call = 0; call < 60; ++call)
    {
        for (BroadPhaseBody& body : scene.mMoving)
            body.mBounds =
                AABB(body.mBounds.mMin + Vec3(0.1f, 0.0f, 0.0f), body.mBounds.mMax + Vec3(0.1f, 0.0f, 0.0f));
        worlds.Move(scene.mMoving);
        worlds.ExpectSamePairs(scene.mActive, "sliding", call % 2 == 0 ? 1 : 2);
    }
    const BroadPhaseQuadTree::CandidateCacheStats stats = worlds.Tested().GetCandidateCacheStats();
    EXPECT_GT(stats.mRefilled, 4 * scene.mActive.size());
    EXPECT_GT(stats.mReused, 40 * scene.mActive.size());
}

TEST(BroadPhaseCandidateCacheTest, ChangesToStaticBodiesAreSeenAtTheNextCall)
{
    // Object layer 2 is static geometry that collides with nothing, in the static tree
    LayerSetup layers(3, 2);
    layers.SetBroadPhaseLayer(Layers::cStatic, BroadPhaseLayers::cStatic);
    layers.SetBroadPhaseLayer(Layers::cMoving, BroadPhaseLayers::cMoving);
    layers.SetBroadPhaseLayer(2, BroadPhaseLayers::cStatic);
    layers.SetCollides(Layers::cStatic, Layers::cMoving, true);
    layers.SetCollides(Layers::cMoving, Layers::cMoving, true);
    ASSERT_TRUE(layers.GetStatus());
    Worlds worlds(layers);
    RestingScene scene(20, 4);
    worlds.Add(scene.mStatics);
    worlds.Add(scene.mMoving);
    const BroadPhaseBody& resting = scene.mMoving[7];
    const BodyID extra(15000, 3);
    const BroadPhaseBody overlapping{extra, Box(resting.mBounds.Center(), 0.1f), Layers::cStatic};
    const BroadPhaseBody away{extra, Box(resting.mBounds.Center() + Vec3(0.0f, 5.0f, 0.0f), 0.1f),
                              Layers::cStatic};
    auto reported = [&]
    {
        const PairList pairs = Worlds::Pairs(worlds.Tested(), scene.mActive, layers);
        return std::find(pairs.begin(), pairs.end(), std::pair(resting.mID, extra)) != pairs.end();
    };

    for (int call = 0; call < 3; ++call)
        worlds.ExpectSamePairs(scene.mActive, "before the changes"); // Fills and reuses the entries
    // Each change is checked on three calls: the first walks the changed tree, the second refills the
    // entries, the third is served from them
    auto expectOnThreeCalls = [&](bool inReported, const char* inWhat)
    {
        for (int call = 0; call < 3; ++call)
        {
            EXPECT_EQ(reported(), inReported) << inWhat << ", call " << call;
            worlds.ExpectSamePairs(scene.mActive, inWhat);
        }
    };
    worlds.Add({overlapping});
    expectOnThreeCalls(true, "a static added inside a cached box");
    worlds.Move({away});
    expectOnThreeCalls(false, "a cached static moved away");
    worlds.Move({overlapping});
    expectOnThreeCalls(true, "moved back");
    worlds.Move({{extra, overlapping.mBounds, 2}});
    expectOnThreeCalls(false, "put in an object layer the body does not collide with");
    worlds.Move({overlapping});
    expectOnThreeCalls(true, "back in the static layer");
    worlds.Remove({extra});
    expectOnThreeCalls(false, "removed");
    // The index again, with another sequence: the same index, another body
    const BodyID reused(extra.GetIndex(), 4);
    worlds.Add({{reused, overlapping.mBounds, Layers::cStatic}});
    const PairList pairs = Worlds::Pairs(worlds.Tested(), scene.mActive, layers);
    EXPECT_NE(std::find(pairs.begin(), pairs.end(), std::pair(resting.mID, reused)), pairs.end());
    worlds.ExpectSamePairs(scene.mActive, "after the index was reused");
    EXPECT_GT(worlds.Tested().GetCandidateCacheStats().mReused, 0u);
}

TEST(BroadPhaseCandidateCacheTest, AnotherCollisionTableOrActiveOrderIsServedExactly)
{
    Worlds worlds;
    RestingScene scene(30, 3);
    worlds.Add(scene.mStatics);
    worlds.Add(scene.mMoving);
    LayerSetup noStatic = LayerSetup::CreateDefault();
    noStatic.SetCollides(Layers::cStatic, Layers::cMoving, false);
    std::vector<BodyID> reversed(scene.mActive.rbegin(), scene.mActive.rend());
    std::vector<BodyID> half(scene.mActive.begin(), scene.mActive.begin() + scene.mActive.size() / 2);
    EXPECT_GT(worlds.ExpectSamePairs(scene.mActive, "first"), 0u);
    EXPECT_EQ(worlds.ExpectSamePairs(scene.mActive, "moving bodies do not collide with static", 1, &noStatic),
              0u);
    worlds.ExpectSamePairs(scene.mActive, "the default table again");
    worlds.ExpectSamePairs(reversed, "the active list reversed", 3);
    worlds.ExpectSamePairs(half, "half of it");
    worlds.ExpectSamePairs(scene.mActive, "all of it again", 2);
    // A body moved from the moving layer into the static one (another tree) and back
    BroadPhaseBody body = scene.mMoving[3];
    body.mLayer = Layers::cStatic;
    worlds.Move({body});
    worlds.ExpectSamePairs(scene.mActive, "a resting box made static");
    worlds.ExpectSamePairs(scene.mActive, "a resting box made static, again");
    body.mLayer = Layers::cMoving;
    worlds.Move({body});
    worlds.ExpectSamePairs(scene.mActive, "and moving again");
}

TEST(BroadPhaseCandidateCacheTest, BodiesAmongManyStaticsAreWalkedExactly)
{
    Worlds worlds;
    // Tiles 0.2 m apart under a 1 m box: about 36 statics in its grown box, more than an entry keeps
    std::vector<BroadPhaseBody> statics;
    uint32_t index = 0;
    for (uint32_t x = 0; x < 40; ++x)
        for (uint32_t z = 0; z < 40; ++z)
            statics.push_back({BodyID(index++, 1), Box(Vec3(0.2f * float(x), -0.05f, 0.2f * float(z)), 0.09f),
                               Layers::cStatic});
    // And one tile far away, for a box with a single candidate
    statics.push_back({BodyID(index++, 1), Box(Vec3(20.0f, -0.5f, 20.0f), 0.5f), Layers::cStatic});
    worlds.Add(statics);
    std::vector<BroadPhaseBody> moving{
        {BodyID(index++, 1), Box(Vec3(4.0f, 0.5f, 4.0f), 0.5f), Layers::cMoving},
        {BodyID(index++, 1), Box(Vec3(20.0f, 0.1f, 20.0f), 0.1f), Layers::cMoving}};
    worlds.Add(moving);
    const std::vector<BodyID> active{moving[0].mID, moving[1].mID};
    for (int call = 0; call < 5; ++call)
        EXPECT_EQ(worlds.ExpectSamePairs(active, "among many statics"), 25u + 1u); // 5 x 5 tiles, and 1
    // Call 1 walks (the static tree was just built), call 2 fills, calls 3 to 5 use the entries
    const BroadPhaseQuadTree::CandidateCacheStats stats = worlds.Tested().GetCandidateCacheStats();
    EXPECT_EQ(stats.mRefilled, 2u);
    EXPECT_EQ(stats.mWalked, 3u) << "the big box has 81 statics in its grown box: walked";
    EXPECT_EQ(stats.mReused, 3u) << "the small one is served from the cache";
}

TEST(BroadPhaseCandidateCacheTest, AFullTableWalksTheRestExactly)
{
    Worlds worlds;
    RestingScene scene(64, 2); // 1,024 resting boxes
    worlds.Add(scene.mStatics);
    worlds.Add(scene.mMoving);
    const size_t half = scene.mActive.size() / 2;
    const std::vector<BodyID> first(scene.mActive.begin(), scene.mActive.begin() + half);
    const std::vector<BodyID> second(scene.mActive.begin() + half, scene.mActive.end());
    worlds.ExpectSamePairs(first, "the first half, walked (the static tree was just built)");
    // 512 entries in a table of 1,024 (not cleared: half full), then 512 other bodies: a quarter of the
    // table is kept free, so 256 of them find no entry
    worlds.ExpectSamePairs(first, "the first half, entries filled");
    worlds.ExpectSamePairs(second, "the second half"); // One thread: two may claim a few over the limit
    EXPECT_EQ(worlds.Tested().GetCandidateCacheStats().mUncached, 256u);
    // The next call finds the table over half full and clears it; the one after needs a larger table: every
    // body gets an entry in both
    worlds.ExpectSamePairs(second, "the second half, after the clear", 2);
    worlds.ExpectSamePairs(scene.mActive, "all, in a new table", 2);
    EXPECT_EQ(worlds.Tested().GetCandidateCacheStats().mUncached, 256u);
    EXPECT_EQ(worlds.Tested().GetCandidateCacheStats().mRefilled, 512u + 256u + 512u + 1024u);
}

TEST(BroadPhaseCandidateCacheTest, ABodyListedTwiceGetsTheReferencePairs)
{
    Worlds worlds;
    RestingScene scene(20, 2);
    worlds.Add(scene.mStatics);
    worlds.Add(scene.mMoving);
    std::vector<BodyID> twice = scene.mActive;
    twice.push_back(scene.mActive[5]); // A caller bug; in another range, so two threads would share its entry
    for (int call = 0; call < 3; ++call)
        worlds.ExpectSamePairs(twice, "a body listed twice", 2);
    worlds.ExpectSamePairs(scene.mActive, "listed once again", 2);
}

} // namespace
} // namespace cairn
