#include "cairn/physics/islands/IslandBuilder.h"

#include <utility>

namespace cairn
{

void IslandBuilder::Prepare(uint32_t inNumBodies)
{
    mParent.resize(inNumBodies);
    for (uint32_t i = 0; i < inNumBodies; ++i)
        mParent[i] = i;
}

uint32_t IslandBuilder::Find(uint32_t inBody)
{
    // Path halving: every visited node skips to its grandparent, keeping later finds short
    while (mParent[inBody] != inBody)
    {
        mParent[inBody] = mParent[mParent[inBody]];
        inBody = mParent[inBody];
    }
    return inBody;
}

void IslandBuilder::Link(uint32_t inA, uint32_t inB)
{
    uint32_t a = Find(inA);
    uint32_t b = Find(inB);
    if (a == b) return;
    // The lower index becomes the root, as the lock-free builder will do
    if (a > b) std::swap(a, b);
    mParent[b] = a;
}

void IslandBuilder::Finalize()
{
    const uint32_t n = uint32_t(mParent.size());
    mIslandOfBody.assign(n, 0);
    mIslandStart.clear();
    // Roots are the lowest index of their set, so numbering roots in index order visits islands in order of
    // their lowest body, and a non-root's root is always numbered before it
    uint32_t numIslands = 0;
    for (uint32_t i = 0; i < n; ++i)
    {
        const uint32_t root = Find(i);
        mIslandOfBody[i] = root == i ? numIslands++ : mIslandOfBody[root];
    }
    // Counting sort of bodies by island
    mIslandStart.assign(numIslands + 1, 0);
    for (uint32_t i = 0; i < n; ++i)
        ++mIslandStart[mIslandOfBody[i] + 1];
    for (uint32_t i = 0; i < numIslands; ++i)
        mIslandStart[i + 1] += mIslandStart[i];
    mBodies.resize(n);
    mCursor.assign(mIslandStart.begin(), mIslandStart.end() - 1);
    for (uint32_t i = 0; i < n; ++i)
        mBodies[mCursor[mIslandOfBody[i]]++] = i;
}

} // namespace cairn
