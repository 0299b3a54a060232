#include "cairn/physics/solver/ContactCache.h"

#include <algorithm>

namespace cairn
{

void ContactCache::BeginStep()
{
    mPrevious.swap(mCurrent);
    mCurrent.clear();
    mPreviousPairs.swap(mCurrentPairs);
    mCurrentPairs.clear();
}

const CachedBodyPair* ContactCache::FindPreviousPair(BodyID inBodyA, BodyID inBodyB) const
{
    const std::pair key(inBodyA, inBodyB);
    auto it = std::lower_bound(mPreviousPairs.begin(), mPreviousPairs.end(), key,
                               [](const CachedBodyPair& inP, const std::pair<BodyID, BodyID>& inK)
                               { return std::pair(inP.mBodyA, inP.mBodyB) < inK; });
    return it != mPreviousPairs.end() && it->mBodyA == inBodyA && it->mBodyB == inBodyB ? &*it : nullptr;
}

const CachedManifold* ContactCache::FindPrevious(const ContactKey& inKey) const
{
    auto it =
        std::lower_bound(mPrevious.begin(), mPrevious.end(), inKey,
                         [](const CachedManifold& inM, const ContactKey& inK) { return inM.mKey < inK; });
    return it != mPrevious.end() && it->mKey == inKey ? &*it : nullptr;
}

uint32_t ContactCache::Add(const CachedManifold& inManifold)
{
    mCurrent.push_back(inManifold);
    return uint32_t(mCurrent.size() - 1);
}

void ContactCache::EndStep()
{
    std::sort(mCurrent.begin(), mCurrent.end(),
              [](const CachedManifold& inA, const CachedManifold& inB) { return inA.mKey < inB.mKey; });
    std::sort(mCurrentPairs.begin(), mCurrentPairs.end(),
              [](const CachedBodyPair& inA, const CachedBodyPair& inB)
              { return std::pair(inA.mBodyA, inA.mBodyB) < std::pair(inB.mBodyA, inB.mBodyB); });
    // A pair's manifolds are now contiguous (the key starts with the bodies) and in the pairs' order: one
    // walk finds where each pair's begin
    uint32_t next = 0;
    for (CachedBodyPair& pair : mCurrentPairs)
    {
        while (next < mCurrent.size() && std::pair(mCurrent[next].mKey.mBodyA, mCurrent[next].mKey.mBodyB) <
                                             std::pair(pair.mBodyA, pair.mBodyB))
            ++next;
        pair.mFirstManifold = next;
        next += pair.mNumManifolds;
    }
}

void ContactCache::Clear()
{
    mPrevious.clear();
    mCurrent.clear();
    mPreviousPairs.clear();
    mCurrentPairs.clear();
}

} // namespace cairn
