// ContactCache: what one step stores, the next finds, whatever order the narrow phase added it in.

#include "solver/ContactCache.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <random>

namespace cairn
{
using namespace cairn::physics;
namespace
{

/// A pair (a, b) with inNumManifolds manifolds, sub-shapes 0.., each impulse marking pair and manifold.
struct StepContent
{
    std::vector<CachedBodyPair> mPairs;
    std::vector<std::vector<CachedManifold>> mManifolds; ///< Per pair
};

StepContent MakeStep(int inNumPairs, uint32_t inSeed)
{
    std::mt19937 random(inSeed);
    StepContent step;
    for (int p = 0; p < inNumPairs; ++p)
    {
        CachedBodyPair pair{};
        pair.mDeltaPosition = Vec3::Zero();
        pair.mDeltaRotation = Quat::Identity();
        pair.mMaxSeparation = 0.0f;
        pair.mBodyA = BodyID(uint32_t(random() % 500), random() % 3);
        pair.mBodyB = BodyID(500 + uint32_t(p), 0); // Unique: no two records of one pair
        pair.mNumManifolds = 1 + random() % 3;
        std::vector<CachedManifold> manifolds;
        for (uint32_t m = 0; m < pair.mNumManifolds; ++m)
        {
            CachedManifold manifold;
            for (int i = 0; i < ContactManifold::cMaxPoints; ++i)
            {
                manifold.mLocalOnA[i] = manifold.mLocalOnB[i] = Vec3::Zero();
                manifold.mNormalImpulse[i] = 0.0f;
            }
            manifold.mKey = {pair.mBodyA, pair.mBodyB, SubShapeID(7 - m), SubShapeID(m)};
            manifold.mNumPoints = 1;
            manifold.mNormalImpulse[0] = float(p) + 0.1f * float(m);
            manifolds.push_back(manifold);
        }
        step.mPairs.push_back(pair);
        step.mManifolds.push_back(manifolds);
    }
    return step;
}

/// Stores inStep as the narrow phase would (each pair, then its manifolds), in inOrder of pairs.
void Store(ContactCache& ioCache, const StepContent& inStep, const std::vector<size_t>& inOrder)
{
    ioCache.BeginStep();
    for (size_t p : inOrder)
    {
        ioCache.AddPair(inStep.mPairs[p]);
        for (const CachedManifold& manifold : inStep.mManifolds[p])
            (void)ioCache.Add(manifold);
    }
    ioCache.EndStep();
    ioCache.BeginStep(); // The next step: what was stored is now "previous"
}

void ExpectAllFound(const ContactCache& inCache, const StepContent& inStep)
{
    for (size_t p = 0; p < inStep.mPairs.size(); ++p)
    {
        const CachedBodyPair& pair = inStep.mPairs[p];
        const CachedBodyPair* found = inCache.FindPreviousPair(pair.mBodyA, pair.mBodyB);
        ASSERT_NE(found, nullptr) << "pair " << p;
        const std::span<const CachedManifold> manifolds = inCache.GetPreviousManifolds(*found);
        ASSERT_EQ(manifolds.size(), inStep.mManifolds[p].size()) << "pair " << p;
        for (const CachedManifold& expected : inStep.mManifolds[p])
        {
            const auto match =
                std::find_if(manifolds.begin(), manifolds.end(),
                             [&](const CachedManifold& inM) { return inM.mKey == expected.mKey; });
            ASSERT_NE(match, manifolds.end()) << "pair " << p;
            EXPECT_EQ(match->mNormalImpulse[0], expected.mNormalImpulse[0]);
            const CachedManifold* byKey = inCache.FindPrevious(expected.mKey);
            ASSERT_NE(byKey, nullptr);
            EXPECT_EQ(byKey->mNormalImpulse[0], expected.mNormalImpulse[0]);
        }
    }
    EXPECT_EQ(inCache.FindPreviousPair(BodyID(9999, 0), BodyID(10000, 0)), nullptr);
}

TEST(ContactCacheTest, FindsWhatTheLastStepStoredInSortedOrder)
{
    const StepContent step = MakeStep(300, 1);
    std::vector<size_t> order(step.mPairs.size());
    for (size_t i = 0; i < order.size(); ++i)
        order[i] = i;
    // The narrow phase's canonical order: by bodies
    std::sort(order.begin(), order.end(),
              [&](size_t inL, size_t inR)
              {
                  return std::pair(step.mPairs[inL].mBodyA, step.mPairs[inL].mBodyB) <
                         std::pair(step.mPairs[inR].mBodyA, step.mPairs[inR].mBodyB);
              });
    ContactCache cache;
    Store(cache, step, order);
    ExpectAllFound(cache, step);
}

TEST(ContactCacheTest, FindsWhatTheLastStepStoredInAnyOrder)
{
    for (uint32_t seed = 1; seed <= 5; ++seed)
    {
        const StepContent step = MakeStep(300, seed);
        std::vector<size_t> order(step.mPairs.size());
        for (size_t i = 0; i < order.size(); ++i)
            order[i] = i;
        std::shuffle(order.begin(), order.end(), std::mt19937(seed));
        ContactCache cache;
        Store(cache, step, order);
        ExpectAllFound(cache, step);
        // A second step over the same cache (its buffers reused) stores and finds as well
        const StepContent next = MakeStep(200, seed + 100);
        std::vector<size_t> nextOrder(next.mPairs.size());
        for (size_t i = 0; i < nextOrder.size(); ++i)
            nextOrder[i] = nextOrder.size() - 1 - i;
        Store(cache, next, nextOrder);
        ExpectAllFound(cache, next);
    }
}

TEST(ContactCacheTest, HintedPairLookupsFindTheSameAsUnhinted)
{
    const StepContent step = MakeStep(500, 7);
    std::vector<size_t> order(step.mPairs.size());
    for (size_t i = 0; i < order.size(); ++i)
        order[i] = i;
    ContactCache cache;
    Store(cache, step, order);
    // Queries: every stored pair and as many absent ones, sorted (as the narrow phase asks), then shuffled
    std::vector<std::pair<BodyID, BodyID>> queries;
    for (const CachedBodyPair& pair : step.mPairs)
    {
        queries.emplace_back(pair.mBodyA, pair.mBodyB);
        queries.emplace_back(pair.mBodyA, BodyID(pair.mBodyB.GetIndex(), 5)); // Another sequence: absent
    }
    queries.emplace_back(BodyID(0, 0), BodyID(0, 0));
    queries.emplace_back(BodyID(100000, 0), BodyID(100001, 0));
    std::sort(queries.begin(), queries.end());
    for (int pass = 0; pass < 2; ++pass)
    {
        uint32_t hint = 0;
        int found = 0;
        for (const auto& [a, b] : queries)
        {
            const CachedBodyPair* unhinted = cache.FindPreviousPair(a, b);
            const CachedBodyPair* hinted = cache.FindPreviousPair(a, b, &hint);
            EXPECT_EQ(hinted, unhinted) << "pass " << pass;
            found += hinted != nullptr ? 1 : 0;
        }
        EXPECT_EQ(found, 500);
        std::shuffle(queries.begin(), queries.end(), std::mt19937(3));
    }
    uint32_t wild = 123456; // Out of range: still right
    EXPECT_NE(cache.FindPreviousPair(step.mPairs[0].mBodyA, step.mPairs[0].mBodyB, &wild), nullptr);
}

} // namespace
} // namespace cairn
