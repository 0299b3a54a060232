#include "cairn/physics/body/CollisionGroup.h"

#include <algorithm>
#include <utility>

namespace cairn::physics
{

GroupFilterTable::GroupFilterTable(uint32_t inNumSubGroups)
    : mNumSubGroups(std::clamp<uint32_t>(inNumSubGroups, 1, cMaxSubGroups))
{
    const size_t pairs = size_t(mNumSubGroups) * (mNumSubGroups - 1) / 2;
    mBits.assign((pairs + 63) / 64, ~uint64_t(0));
}

size_t GroupFilterTable::BitOf(uint32_t inA, uint32_t inB) const
{
    // Rows 0 .. a-1 hold (n-1) + (n-2) + ... + (n-a) pairs
    const size_t a = inA, n = mNumSubGroups;
    return a * (2 * n - a - 1) / 2 + (inB - inA - 1);
}

void GroupFilterTable::Set(uint32_t inA, uint32_t inB, bool inCollide)
{
    if (inA > inB) std::swap(inA, inB);
    if (inA == inB || inB >= mNumSubGroups) return; // A part never meets itself; out of range: ignored
    const size_t bit = BitOf(inA, inB);
    if (inCollide)
        mBits[bit / 64] |= uint64_t(1) << (bit % 64);
    else
        mBits[bit / 64] &= ~(uint64_t(1) << (bit % 64));
}

bool GroupFilterTable::CanCollide(uint32_t inA, uint32_t inB) const
{
    if (inA > inB) std::swap(inA, inB);
    if (inA == inB || inB >= mNumSubGroups) return true;
    const size_t bit = BitOf(inA, inB);
    return (mBits[bit / 64] >> (bit % 64) & 1) != 0;
}

} // namespace cairn::physics
