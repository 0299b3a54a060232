#pragma once

// IslandBuilder: groups active dynamic bodies connected by contacts into simulation islands, with a plain
// sequential union-find (union by lower index, path halving). Static and kinematic bodies never join an
// island: the caller only links pairs of dynamic bodies. Physics step only (one thread): no locks. Bodies are
// named by their dense index in the active list.

#include <cstdint>
#include <span>
#include <vector>

namespace cairn
{

class IslandBuilder
{
public:
    /// Starts a step with inNumBodies bodies, each its own island.
    void Prepare(uint32_t inNumBodies);
    /// Connects two bodies (active-list indices).
    void Link(uint32_t inA, uint32_t inB);
    /// Numbers the islands 0..N-1 in order of their lowest body (deterministic) and lists their bodies.
    void Finalize();

    uint32_t GetNumIslands() const { return uint32_t(mIslandStart.size()) - 1; }
    /// Island of a body; valid after Finalize.
    uint32_t GetIsland(uint32_t inBody) const { return mIslandOfBody[inBody]; }
    /// Bodies of an island (active-list indices), ascending; valid after Finalize.
    std::span<const uint32_t> GetBodies(uint32_t inIsland) const
    {
        return {mBodies.data() + mIslandStart[inIsland], mBodies.data() + mIslandStart[inIsland + 1]};
    }

private:
    uint32_t Find(uint32_t inBody);

    std::vector<uint32_t> mParent;       ///< Union-find links; roots are the lowest index of their set
    std::vector<uint32_t> mIslandOfBody; ///< Island number per body
    std::vector<uint32_t> mIslandStart;  ///< Offsets into mBodies, one past the end for the last island
    std::vector<uint32_t> mBodies;       ///< Bodies grouped by island
    std::vector<uint32_t> mCursor;       ///< Scratch for the counting sort, kept to avoid allocating per step
};

} // namespace cairn
