#include "HutLadders.h"

#include "Buildings.h"
#include "WorldGenerator.h"

#include <set>

namespace cairn::demo
{
using namespace cairn::physics;

namespace
{
/// How far each foot stands from the back wall's face on its side (m): clear of the wall by more than an
/// agent's radius, within the hut's footprint outside
constexpr float cFootFromWall = 1.2f;
} // namespace

HutLadders::HutLadders(const TileStreamer& inStreamer, const WorldGenerator& inGenerator,
                       navmesh::TileScheduler& ioHumanScheduler)
    : mStreamer(inStreamer), mGenerator(inGenerator), mScheduler(ioHumanScheduler)
{
}

HutLadders::~HutLadders()
{
    for (const auto& [door, link] : mLadders)
        mScheduler.RemoveOffMeshLink(link);
}

navmesh::OffMeshLink MakeHutLadder(const Vec3& inOutside, const Vec3& inInside,
                                   const WorldGenerator& inGenerator)
{
    // Into the room, level: from the point outside the doorway to the one inside
    Vec3 inward = inInside - inOutside;
    inward.y() = 0.0f;
    inward.normalize();
    // The doorway is in the front wall, half the hut from its middle
    const Vec3 middle = inOutside + inward * (cDoorOutsideDistance + cBuildingHalfSize);
    const auto onGround = [&](float inFromMiddle)
    {
        const Vec3 point = middle + inward * inFromMiddle;
        return Vec3(point.x(), inGenerator.GetTerrainHeight(point.x(), point.z()), point.z());
    };
    navmesh::OffMeshLink ladder;
    ladder.mStart = onGround(cBuildingHalfSize + cFootFromWall);
    ladder.mEnd = onGround(cBuildingHalfSize - cWallThickness - cFootFromWall);
    ladder.mRadius = 0.6f;
    ladder.mBidirectional = true;
    ladder.mArea = cLadderArea;
    return ladder;
}

HutLadders::States HutLadders::CountStates() const
{
    States states;
    for (const auto& [panel, link] : mLadders)
    {
        const Result<navmesh::OffMeshLinkState> state = mScheduler.GetOffMeshLinkState(link);
        using enum navmesh::OffMeshLinkState;
        if (state && state.Value() == Joined)
            ++states.mJoined;
        else if (state && (state.Value() == Pending || state.Value() == StartTileMissing ||
                           state.Value() == EndTileMissing))
            ++states.mWaiting;
        else
            ++states.mDead;
    }
    return states;
}

void HutLadders::Update()
{
    if (!mStreamer.TakeDoorsIfChanged(mDoorsVersion, mDoors)) return;
    std::set<BodyID> present;
    for (const StreamedDoor& door : mDoors)
    {
        present.insert(door.mPanel);
        if (mLadders.contains(door.mPanel)) continue;
        Result<navmesh::TileScheduler::LinkID> link =
            mScheduler.AddOffMeshLink(MakeHutLadder(door.mOutside, door.mInside, mGenerator));
        if (link)
            mLadders.emplace(door.mPanel, link.Value());
        else
            ++mRefused;
    }
    for (auto it = mLadders.begin(); it != mLadders.end();)
    {
        if (present.contains(it->first))
        {
            ++it;
            continue;
        }
        mScheduler.RemoveOffMeshLink(it->second);
        it = mLadders.erase(it);
    }
    mMostLadders = std::max(mMostLadders, uint32_t(mLadders.size()));
}

} // namespace cairn::demo
