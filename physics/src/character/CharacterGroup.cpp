#include "cairn/physics/character/CharacterGroup.h"

#include "cairn/physics/character/CharacterController.h"
#include "character/CharacterGroupQueries.h"

#include <algorithm>
#include <cmath>

namespace cairn::physics
{

Result<CharacterGroup::MemberID> CharacterGroup::Add(CharacterController& ioCharacter)
{
    if (ioCharacter.mSeat.mGroup != nullptr)
        return MakeError(ErrorCode::AlreadyAdded,
                         "character group: the character is a member of a group already");
    if (mNumMembers >= cMaxMembers)
        return MakeError(ErrorCode::OutOfCapacity,
                         "character group: it holds " + std::to_string(cMaxMembers) + " members already");
    MemberID member;
    if (!mFree.empty())
    {
        member = mFree.back();
        mFree.pop_back();
    }
    else
    {
        member = MemberID(mMembers.size());
        mMembers.emplace_back();
    }
    mMembers[member] = {ioCharacter.mSettings.mShape,
                        ioCharacter.mShapeRotation,
                        BoundingRadius(*ioCharacter.mSettings.mShape),
                        ioCharacter.mPosition,
                        ioCharacter.mPosition,
                        &ioCharacter.mSeat,
                        mNextSerial++};
    ++mNumMembers;
    ioCharacter.mSeat.mGroup = this;
    ioCharacter.mSeat.mMember = member;
    // Seen from now on: outside the grid until the next Publish builds it, so adding many costs no rebuilds
    mUnplaced.push_back(member);
    mMaxRadius = std::max(mMaxRadius, mMembers[member].mRadius);
    return member;
}

Status CharacterGroup::Remove(CharacterController& ioCharacter)
{
    if (ioCharacter.mSeat.mGroup != this)
        return MakeError(ErrorCode::NotAdded, "character group: the character is not a member of this group");
    ioCharacter.mSeat.Leave();
    return Status::Ok();
}

CharacterGroup::~CharacterGroup()
{
    for (Member& member : mMembers)
        if (member.mSeat != nullptr)
        {
            member.mSeat->mGroup = nullptr;
            member.mSeat->mMember = cNoMember;
        }
}

CharacterGroup::Seat::Seat(Seat&& ioOther) noexcept
{
    TakeOver(ioOther);
}

CharacterGroup::Seat& CharacterGroup::Seat::operator=(const Seat& inOther)
{
    if (this != &inOther) Leave(); // It becomes a copy, which is in no group
    return *this;
}

CharacterGroup::Seat& CharacterGroup::Seat::operator=(Seat&& ioOther) noexcept
{
    if (this != &ioOther)
    {
        Leave();
        TakeOver(ioOther);
    }
    return *this;
}

void CharacterGroup::Seat::TakeOver(Seat& ioOther)
{
    mGroup = ioOther.mGroup;
    mMember = ioOther.mMember;
    ioOther.mGroup = nullptr;
    ioOther.mMember = cNoMember;
    if (mGroup != nullptr)
        mGroup->mMembers[mMember].mSeat = this; // The group finds the place where it is now
}

void CharacterGroup::Seat::Leave()
{
    if (mGroup != nullptr) mGroup->Leave(mMember);
    mGroup = nullptr;
    mMember = cNoMember;
}

void CharacterGroup::Leave(MemberID inMember)
{
    // Its cell in the grid, or its place among the unplaced, stays till the next Publish: a free slot is
    // passed over, and a slot taken again is looked at where its new member stands
    mMembers[inMember] = Member{};
    mFree.push_back(inMember);
    --mNumMembers;
}

void CharacterGroup::Publish()
{
    for (Member& member : mMembers)
        member.mPublished = member.mNext;
    BuildGrid();
}

namespace
{
/// Cell coordinates packed 21 bits each
constexpr int64_t cCellRange = (int64_t(1) << 20) - 1;

/// A coordinate's cell, clamped to the keys' range before it is made an integer (a coordinate past the
/// world's edge would overflow it)
int64_t CellOf(float inCoordinate, float inCellSize)
{
    const float cell = std::floor(inCoordinate / inCellSize);
    if (!(cell > float(-cCellRange))) return -cCellRange;
    if (!(cell < float(cCellRange))) return cCellRange;
    return int64_t(cell);
}

uint64_t CellKey(int64_t inX, int64_t inY, int64_t inZ)
{
    const auto field = [](int64_t inValue) { return uint64_t(inValue + cCellRange); };
    return field(inX) << 42 | field(inY) << 21 | field(inZ);
}
} // namespace

void CharacterGroup::BuildGrid()
{
    mMaxRadius = 0.0f;
    for (const Member& member : mMembers)
        mMaxRadius = std::max(mMaxRadius, member.mRadius);
    mCellSize = std::max(2.0f * mMaxRadius, cMinCellSize);
    mGrid.clear();
    mUnplaced.clear();
    for (MemberID member = 0; member < MemberID(mMembers.size()); ++member)
    {
        const Vec3& at = mMembers[member].mPublished;
        if (mMembers[member].mShape != nullptr)
            mGrid.emplace_back(
                CellKey(CellOf(at.x(), mCellSize), CellOf(at.y(), mCellSize), CellOf(at.z(), mCellSize)),
                member);
    }
    std::sort(mGrid.begin(), mGrid.end());
}

void CharacterGroup::Visit(MemberID inMember, MemberVisitor inVisit) const
{
    const Member& member = mMembers[inMember];
    if (member.mShape != nullptr)
        inVisit(inMember, *member.mShape, Transform{member.mPublished, member.mRotation}, member.mRadius);
}

void CharacterGroup::ForEachMemberNear(const AABB& inBounds, MemberVisitor inVisit) const
{
    // Bounds that are not numbers hold no cells to look in: every member is looked at
    if (!IsFinite(inBounds.mMin) || !IsFinite(inBounds.mMax))
    {
        ForEachMember(inVisit);
        return;
    }
    // Grown by the widest member's radius (since an Add, wider than the grid's cells: still every cell a
    // member in the grid reaches from)
    const AABB reach = inBounds.Expanded(mMaxRadius);
    int64_t low[3], high[3];
    uint64_t cells = 1;
    for (int axis = 0; axis < 3; ++axis)
    {
        low[axis] = CellOf(reach.mMin[axis], mCellSize);
        high[axis] = CellOf(reach.mMax[axis], mCellSize);
        cells *= uint64_t(high[axis] - low[axis] + 1);
    }
    // A long move crosses more cells than there are members: each member once is less work
    if (cells > mGrid.size() + mUnplaced.size())
    {
        ForEachMember(inVisit);
        return;
    }
    for (const MemberID member : mUnplaced)
        Visit(member, inVisit);
    // A row of cells along z has consecutive keys (z is the key's lowest field): one search a row
    for (int64_t x = low[0]; x <= high[0]; ++x)
        for (int64_t y = low[1]; y <= high[1]; ++y)
        {
            const uint64_t last = CellKey(x, y, high[2]);
            auto cell = std::lower_bound(mGrid.begin(), mGrid.end(),
                                         std::make_pair(CellKey(x, y, low[2]), MemberID(0)));
            for (; cell != mGrid.end() && cell->first <= last; ++cell)
                Visit(cell->second, inVisit);
        }
}

void CharacterGroup::ForEachMember(MemberVisitor inVisit) const
{
    for (MemberID member = 0; member < MemberID(mMembers.size()); ++member)
        Visit(member, inVisit);
}

} // namespace cairn::physics
