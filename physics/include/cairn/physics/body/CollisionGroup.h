#pragma once

// Which parts of one object collide with each other: a ragdoll's limbs that a joint holds together overlap at
// the joint and must not push apart, while an arm may still hit a leg (Jolt's GroupFilterTable, PhysX's
// collision groups). Layers (Layers.h) say which kinds of bodies meet; a group refines that within one
// object.
//
// Threads: a GroupFilterTable is filled by its maker, then shared read-only by its bodies (a
// std::shared_ptr<const>): the narrow phase reads it from any step thread, no lock.

#include <cstdint>
#include <memory>
#include <vector>

namespace cairn::physics
{

/// For the parts (sub-groups) of one group, which pairs collide: all of them at first.
class GroupFilterTable
{
public:
    /// At most this many parts: the table is a bit per pair, and a bad count gets no memory to match.
    static constexpr uint32_t cMaxSubGroups = 4096;

    /// inNumSubGroups within [1, cMaxSubGroups] (clamped there).
    explicit GroupFilterTable(uint32_t inNumSubGroups);
    uint32_t GetNumSubGroups() const { return mNumSubGroups; }
    /// Parts out of range are ignored (a table is made before it is shared: no error path to take).
    void DisableCollision(uint32_t inA, uint32_t inB) { Set(inA, inB, false); }
    void EnableCollision(uint32_t inA, uint32_t inB) { Set(inA, inB, true); }
    /// Whether parts inA and inB collide; a part out of range collides with everything.
    bool CanCollide(uint32_t inA, uint32_t inB) const;

private:
    void Set(uint32_t inA, uint32_t inB, bool inCollide);
    /// The bit of the pair (a, b), a < b: row a's pairs after the rows before it
    size_t BitOf(uint32_t inA, uint32_t inB) const;

    uint32_t mNumSubGroups;
    std::vector<uint64_t> mBits; ///< Set: the pair collides
};

/// A body's group: bodies of different groups, or of none, collide as their layers say; two bodies of one
/// group collide as the group's table says, and not at all where the group has no table.
struct CollisionGroup
{
    static constexpr uint32_t cNoGroup = 0xffffffffu;
    std::shared_ptr<const GroupFilterTable> mFilter; ///< Shared by the group's bodies (null: none collide)
    uint32_t mGroupID = cNoGroup;
    uint32_t mSubGroupID = 0; ///< Below the table's GetNumSubGroups
};

/// Whether two bodies with these groups may collide (their layers aside).
inline bool GroupsCollide(const CollisionGroup& inA, const CollisionGroup& inB)
{
    if (inA.mGroupID == CollisionGroup::cNoGroup || inA.mGroupID != inB.mGroupID) return true;
    const GroupFilterTable* table = inA.mFilter != nullptr ? inA.mFilter.get() : inB.mFilter.get();
    return table != nullptr && table->CanCollide(inA.mSubGroupID, inB.mSubGroupID);
}

} // namespace cairn::physics
