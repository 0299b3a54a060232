#include "solver/ContactCache.h"

#include <algorithm>

namespace cairn::physics
{

void ContactCache::BeginStep()
{
    mPrevious.swap(mCurrent);
    mCurrent.clear();
    mPreviousPairs.swap(mCurrentPairs);
    mCurrentPairs.clear();
}

const CachedBodyPair* ContactCache::FindPreviousPair(BodyID inBodyA, BodyID inBodyB, uint32_t* ioHint) const
{
    const std::pair key(inBodyA, inBodyB);
    auto less = [](const CachedBodyPair& inP, const std::pair<BodyID, BodyID>& inK)
    { return std::pair(inP.mBodyA, inP.mBodyB) < inK; };
    const size_t count = mPreviousPairs.size();
    size_t begin = 0, end = count;
    if (ioHint != nullptr && *ioHint < count)
    {
        // Lookups in the narrow phase's pair order come in increasing order: gallop from the last one
        const size_t hint = *ioHint;
        if (less(mPreviousPairs[hint], key))
        {
            begin = hint + 1; // Everything before begin is below the key
            size_t step = 1;
            while (hint + step < count && less(mPreviousPairs[hint + step], key))
            {
                begin = hint + step + 1;
                step *= 2;
            }
            end = std::min(hint + step + 1, count); // mPreviousPairs[hint + step] is not below the key
        }
        else if (hint == 0 || less(mPreviousPairs[hint - 1], key))
            begin = end = hint; // The key belongs right at the hint (a new pair between two cached ones)
        else
            end = hint + 1; // mPreviousPairs[hint] is not below the key
    }
    const auto it = std::lower_bound(mPreviousPairs.begin() + ptrdiff_t(begin),
                                     mPreviousPairs.begin() + ptrdiff_t(end), key, less);
    if (ioHint != nullptr) *ioHint = uint32_t(it - mPreviousPairs.begin());
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

namespace
{
/// Sorts ioItems by inKeyOf (ties by position, so the order is the same everywhere). The narrow phase adds
/// them in its canonical pair order, which is nearly always sorted already: then one check is all. Otherwise
/// the keys are sorted with their positions and the items moved once, where sorting the items themselves
/// (up to 200 bytes each) moved each of them log n times.
template <class Items, class Key, class KeyOf>
void SortByKey(Items& ioItems, Items& ioScratch, std::vector<std::pair<Key, uint32_t>>& ioOrder,
               const KeyOf& inKeyOf)
{
    using Item = typename Items::value_type;
    if (std::is_sorted(ioItems.begin(), ioItems.end(),
                       [&](const Item& inA, const Item& inB) { return inKeyOf(inA) < inKeyOf(inB); }))
        return;
    ioOrder.resize(ioItems.size());
    for (size_t i = 0; i < ioItems.size(); ++i)
        ioOrder[i] = {inKeyOf(ioItems[i]), uint32_t(i)};
    std::sort(ioOrder.begin(), ioOrder.end());
    ioScratch.resize(ioItems.size());
    for (size_t i = 0; i < ioOrder.size(); ++i)
        ioScratch[i] = ioItems[ioOrder[i].second];
    ioItems.swap(ioScratch);
}
} // namespace

void ContactCache::EndStep(bool inInOrder)
{
    if (inInOrder) return;
    SortByKey(mCurrent, mScratch, mManifoldOrder, [](const CachedManifold& inM) { return inM.mKey; });
    SortByKey(mCurrentPairs, mScratchPairs, mPairOrder,
              [](const CachedBodyPair& inP) { return std::pair(inP.mBodyA, inP.mBodyB); });
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

bool ContactCache::IsConsistent() const
{
    for (size_t i = 1; i < mCurrent.size(); ++i)
        if (!(mCurrent[i - 1].mKey < mCurrent[i].mKey)) return false;
    uint32_t next = 0;
    for (size_t i = 0; i < mCurrentPairs.size(); ++i)
    {
        const CachedBodyPair& pair = mCurrentPairs[i];
        if (i > 0 && !(std::pair(mCurrentPairs[i - 1].mBodyA, mCurrentPairs[i - 1].mBodyB) <
                       std::pair(pair.mBodyA, pair.mBodyB)))
            return false;
        if (pair.mFirstManifold != next || pair.mFirstManifold + pair.mNumManifolds > mCurrent.size())
            return false;
        for (uint32_t m = pair.mFirstManifold; m < pair.mFirstManifold + pair.mNumManifolds; ++m)
            if (mCurrent[m].mKey.mBodyA != pair.mBodyA || mCurrent[m].mKey.mBodyB != pair.mBodyB)
                return false;
        next += pair.mNumManifolds;
    }
    return next == mCurrent.size();
}

void ContactCache::Clear()
{
    mPrevious.clear();
    mCurrent.clear();
    mPreviousPairs.clear();
    mCurrentPairs.clear();
}

} // namespace cairn::physics
