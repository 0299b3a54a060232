#include "islands/AtomicUnionFind.h"

#include <algorithm>

namespace cairn::physics
{

void AtomicUnionFind::Reset(uint32_t inNumBodies)
{
    if (inNumBodies > mCapacity)
    {
        mLinks = std::make_unique<std::atomic<uint32_t>[]>(inNumBodies);
        mCapacity = inNumBodies;
        // Room for the most islands possible (one per body), so Finalize never allocates
        mIslandOfBody.reserve(inNumBodies);
        mIslandStart.reserve(inNumBodies + 1);
        mBodies.reserve(inNumBodies);
        mCursor.reserve(inNumBodies);
    }
    mNumBodies = inNumBodies;
    for (uint32_t i = 0; i < inNumBodies; ++i)
        mLinks[i].store(i,
                        std::memory_order_relaxed); // One thread: the start of the Union threads publishes it
    // Results of the previous step are stale: show no islands until Finalize
    mIslandStart.assign(1, 0);
    mIslandOfBody.clear();
    mBodies.clear();
}

void AtomicUnionFind::Grow(uint32_t inNumBodies)
{
    if (inNumBodies <= mNumBodies) return;
    if (inNumBodies > mCapacity)
    {
        const uint32_t capacity = std::max(inNumBodies, 2 * mCapacity);
        auto links = std::make_unique<std::atomic<uint32_t>[]>(capacity);
        for (uint32_t i = 0; i < mNumBodies; ++i)
            links[i].store(mLinks[i].load(std::memory_order_relaxed),
                           std::memory_order_relaxed); // One thread
        mLinks = std::move(links);
        mCapacity = capacity;
        mIslandOfBody.reserve(capacity);
        mIslandStart.reserve(capacity + 1);
        mBodies.reserve(capacity);
        mCursor.reserve(capacity);
    }
    for (uint32_t i = mNumBodies; i < inNumBodies; ++i)
        mLinks[i].store(i, std::memory_order_relaxed); // One thread, as in Reset
    mNumBodies = inNumBodies;
}

void AtomicUnionFind::Finalize()
{
    const uint32_t n = mNumBodies;
    mIslandOfBody.resize(n);
    // A link always points to a lower body of the same island, so in index order the linked body is already
    // numbered: one pass, no Find. Roots are the lowest body of their island, so islands are numbered in
    // order of their lowest body
    uint32_t numIslands = 0;
    for (uint32_t i = 0; i < n; ++i)
    {
        // Relaxed: the Union threads were joined before Finalize, which orders all their writes before this
        const uint32_t link = mLinks[i].load(std::memory_order_relaxed);
        mIslandOfBody[i] = link == i ? numIslands++ : mIslandOfBody[link];
    }
    // Counting sort of bodies by island; scanning bodies in index order keeps each island ascending
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

} // namespace cairn::physics
