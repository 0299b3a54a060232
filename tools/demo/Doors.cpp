// Doors: the huts' doors on their timers, and the rebuilds they cause (see Doors.h).

#include "Doors.h"

#include "Buildings.h"
#include "HutLadders.h"

#include <cmath>
#include <set>

namespace cairn::demo
{
using namespace cairn::physics;

namespace
{
/// How near the hinge's angle must be to closed or open for the doorway check to expect that (rad)
constexpr float cAngleTolerance = 0.1f;
/// A path's end must come this near the asked-for point to count as through the doorway (m)
constexpr float cThroughTolerance = 0.5f;
/// How far the doorway's ground points may be snapped onto the navmesh: less than the wall is thick plus
/// the agent's radius, so that a point in a shut room never snaps to the path outside it (half extents, m)
const Vec3 cDoorwaySnap(0.5f, 2.0f, 0.5f);
} // namespace

Doors::Doors(PhysicsSystem& ioPhysics, const TileStreamer& inStreamer,
             const std::array<const navmesh::NavMeshWorld*, cNumProfiles>& inNavMeshes,
             const std::array<const navmesh::TileScheduler*, cNumProfiles>& inSchedulers)
    : mPhysics(ioPhysics), mStreamer(inStreamer), mNavMeshes(inNavMeshes), mSchedulers(inSchedulers)
{
}

void Doors::RefreshDoors()
{
    if (!mStreamer.TakeDoorsIfChanged(mDoorsVersion, mStreamed)) return;
    std::set<BodyID> present;
    for (const StreamedDoor& door : mStreamed)
    {
        present.insert(door.mPanel);
        auto [it, inserted] = mDoors.try_emplace(door.mPanel);
        if (!inserted) continue;
        it->second.mDoor = door;
        ++mStats.mDoorsSeen;
    }
    std::erase_if(mDoors, [&](const auto& inEntry) { return !present.contains(inEntry.first); });
}

void Doors::Command(float inSeconds)
{
    RefreshDoors();
    ConstraintInterface& joints = mPhysics.GetConstraintInterface();
    for (auto& [panel, state] : mDoors)
    {
        const float period = state.mDoor.mPeriod;
        const bool open = std::fmod(inSeconds + state.mDoor.mPhase, period) >= 0.5f * period;
        if (open == state.mOpen) continue;
        state.mOpen = open;
        ++mStats.mCommands;
        if (Status commanded = joints.SetMotor(state.mDoor.mHinge, DoorMotor(open)); !commanded)
        {
            // The loading thread may have removed the door's tile since the list was taken: its ids went
            // stale. A door still in the world that refuses its motor is a bug
            Result<bool> added = mPhysics.GetBodyInterface().IsAdded(panel);
            if (added && added.Value() && mStats.mErrors.size() < cMaxStatsErrors)
                mStats.mErrors.push_back("door motor: " + commanded.GetError().mMessage);
        }
    }
}

void Doors::AfterStep()
{
    BodyInterface& bodies = mPhysics.GetBodyInterface();
    ConstraintInterface& joints = mPhysics.GetConstraintInterface();
    for (auto& [panel, state] : mDoors)
    {
        Result<bool> active = bodies.IsActive(panel);
        if (!active) continue; // Gone with its tile since the list was taken
        const bool awake = active.Value();
        if (awake && !state.mAwake && state.mRest != 0) mRests[state.mRest - 1].mValid = false;
        const bool cameToRest = state.mAwake && !awake;
        state.mAwake = awake;
        if (!cameToRest) continue;
        ++mStats.mRests;
        Result<AABB> bounds = bodies.GetWorldBounds(panel);
        Result<float> angle = joints.GetPosition(state.mDoor.mHinge);
        if (!bounds || !angle) continue;
        Rest rest;
        rest.mPanel = panel;
        rest.mAngle = angle.Value();
        rest.mOutside = state.mDoor.mOutside;
        rest.mInside = state.mDoor.mInside;
        const size_t index = mRests.size();
        for (int p = 0; p < cNumProfiles; ++p)
        {
            // A tile not built yet gets the door in its first build: only rebuilds of built tiles count
            std::vector<navmesh::TileCoord> tiles;
            mNavMeshes[p]->GetGrid().TilesOverlapping(bounds.Value(), 0.0f, tiles, 16);
            const uint64_t restFrame = mSchedulers[p]->GetFrame() + 1;
            for (const navmesh::TileCoord& tile : tiles)
                if (mSchedulers[p]->GetLastPublication(tile))
                {
                    mWatched.push_back({index, p, tile, restFrame});
                    rest.mWaiting += p == 0 ? 1 : 0;
                }
        }
        if (rest.mWaiting == 0) rest.mValid = false; // Nothing of profile 0 built under it: no check
        mRests.push_back(rest);
        state.mRest = index + 1;
    }
}

void Doors::AfterNavMeshUpdate()
{
    std::erase_if(mWatched,
                  [&](const WatchedTile& inWatched)
                  {
                      const std::optional<navmesh::TileScheduler::Publication> publication =
                          mSchedulers[inWatched.mProfile]->GetLastPublication(inWatched.mTile);
                      Rest& rest = mRests[inWatched.mRest];
                      if (!publication)
                      {
                          ++mStats.mDroppedBeforeRebuild;
                          if (inWatched.mProfile == 0) rest.mValid = false;
                          return true;
                      }
                      if (publication->mBuildStartFrame < inWatched.mRestFrame) return false;
                      ++mStats.mRebuilds;
                      mStats.mLatencyFrames.push_back(
                          uint32_t(publication->mPublishFrame - inWatched.mRestFrame));
                      if (inWatched.mProfile == 0 && --rest.mWaiting == 0)
                      {
                          if (rest.mValid)
                              CheckDoorway(rest);
                          else
                              ++mStats.mChecksSkipped;
                      }
                      return true;
                  });
}

void Doors::CheckDoorway(const Rest& inRest)
{
    const bool closed = std::abs(inRest.mAngle) < cAngleTolerance;
    const bool open = std::abs(inRest.mAngle - cDoorOpenAngle) < cAngleTolerance;
    Result<navmesh::PathResult> path =
        // Climbing no ladder: over one, a shut door would not shut the hut
        mNavMeshes[0]->FindPath(inRest.mOutside, inRest.mInside, NoClimbing(), cDoorwaySnap);
    if ((!closed && !open) || !path)
    {
        ++mStats.mChecksSkipped;
        return;
    }
    const navmesh::PathResult& result = path.Value();
    const bool through = result.mReachedEnd && !result.mStraightPath.empty() &&
                         (result.mStraightPath.back() - inRest.mInside).norm() < cThroughTolerance;
    if (closed)
    {
        ++mStats.mClosedChecks;
        mStats.mClosedBlocked += through ? 0 : 1;
    }
    else
    {
        ++mStats.mOpenChecks;
        mStats.mOpenPassable += through ? 1 : 0;
    }
}

} // namespace cairn::demo
