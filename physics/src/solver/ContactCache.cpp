#include "cairn/physics/solver/ContactCache.h"

#include <algorithm>

namespace cairn
{

void ContactCache::BeginStep()
{
    mPrevious.swap(mCurrent);
    mCurrent.clear();
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
}

void ContactCache::Clear()
{
    mPrevious.clear();
    mCurrent.clear();
}

} // namespace cairn
