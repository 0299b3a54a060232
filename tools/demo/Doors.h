#pragma once

// Doors: the main thread's side of the huts' doors (Buildings.h), as a game's door logic and a check of what
// the navmesh made of them.
//  - Command, before the step: each door opens and closes on its timer (half its period each), by its
//    hinge's position motor (SetMotor wakes it).
//  - AfterStep: the doors that came to rest in the step (awake before, asleep now). The navmesh's schedulers
//    heard of it (a sleeping dynamic body is an obstacle: its tiles turned dirty); for each profile, the
//    tiles under the door that are built and kept now are watched.
//  - AfterNavMeshUpdate, after the sync point: a watched tile's first publication whose build started after
//    the rest is the door-caused rebuild; its latency is counted from the rest's step. Once every watched
//    tile of the human profile is rebuilt, a path is asked through the doorway: blocked when the hinge rests
//    closed, through when it rests open (the navmesh saw the door where it is).
//
// Threads: the main thread only, outside the physics step; it owns everything here. The door list comes
// from the loading thread through TileStreamer::TakeDoorsIfChanged (a try-lock: never waits).

#include "DemoResult.h"
#include "TileStreamer.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/navmesh/TileScheduler.h"
#include "cairn/physics/PhysicsSystem.h"

#include <array>
#include <map>
#include <vector>

namespace cairn::demo
{
using namespace cairn::physics;

class Doors
{
public:
    static constexpr int cNumProfiles = 2;
    /// Profile 0 is the one the doorway checks use (the human agents').
    Doors(PhysicsSystem& ioPhysics, const TileStreamer& inStreamer,
          const std::array<const navmesh::NavMeshWorld*, cNumProfiles>& inNavMeshes,
          const std::array<const navmesh::TileScheduler*, cNumProfiles>& inSchedulers);

    /// Opens or closes the doors whose timer says so at inSeconds of the run.
    void Command(float inSeconds);
    /// Notes the doors that came to rest in the step just done.
    void AfterStep();
    /// Finds the watched tiles' rebuilds and checks the doorways whose tiles are all rebuilt.
    void AfterNavMeshUpdate();

    const DoorStats& GetStats() const { return mStats; }

private:
    struct DoorState
    {
        StreamedDoor mDoor;
        bool mOpen = false; ///< What its motor was last told (a new door is closed)
        bool mAwake = true; ///< As last seen (its hinge woke it when it was made)
        uint64_t mRest = 0; ///< Its latest rest (an index into mRests + 1), 0 for none
    };
    struct Rest
    {
        BodyID mPanel;
        int mWaiting = 0;    ///< Watched tiles of profile 0 not yet rebuilt
        bool mValid = true;  ///< False once the door moved again (the check is skipped)
        float mAngle = 0.0f; ///< The hinge's angle when it came to rest
        Vec3 mOutside = Vec3::Zero();
        Vec3 mInside = Vec3::Zero();
    };
    struct WatchedTile
    {
        size_t mRest = 0; ///< Index into mRests
        int mProfile = 0;
        navmesh::TileCoord mTile;
        uint64_t mRestFrame = 0; ///< The scheduler's frame whose Update is the first after the rest
    };

    /// Takes the streamer's door list when it changed: new doors are added, gone doors forgotten.
    void RefreshDoors();
    /// The doorway path check of a rest whose profile-0 tiles are all rebuilt.
    void CheckDoorway(const Rest& inRest);

    PhysicsSystem& mPhysics;
    const TileStreamer& mStreamer;
    std::array<const navmesh::NavMeshWorld*, cNumProfiles> mNavMeshes;
    std::array<const navmesh::TileScheduler*, cNumProfiles> mSchedulers;
    uint64_t mDoorsVersion = 0;
    std::vector<StreamedDoor> mStreamed; ///< The latest list taken
    std::map<BodyID, DoorState> mDoors;
    std::vector<Rest> mRests;
    std::vector<WatchedTile> mWatched;
    DoorStats mStats;
};

} // namespace cairn::demo
