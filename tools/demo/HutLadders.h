#pragma once

// HutLadders: a ladder over the back wall of every hut (Buildings.h), an off-mesh link of the human navmesh
// that its agents climb in or out by when that way is shorter than the doorway's, or the door is shut. The
// crowd takes them as any link (Crowd: walked to and over); the large agents have none. Each hut's ladder is
// declared to the human TileScheduler when its hut streams in and withdrawn when it goes, so the link lives
// in whichever tile its foot outside is built into.
//
// The ladder's two feet: 1.2 m behind the back wall, outside, and 1.2 m in front of its inner face, inside,
// on the terrain (a hut has no floor of its own). The hut's footprint keeps props away from both.
//
// Threads: the main thread only, outside the physics step and before the navmesh's sync point; the door
// list comes from the loading thread through TileStreamer::TakeDoorsIfChanged (a try-lock: never waits).

#include "TileStreamer.h"
#include "cairn/navmesh/TileScheduler.h"

#include <map>

namespace cairn::demo
{
using namespace cairn::physics;

class WorldGenerator;

/// The navmesh area of the ladders: a path that may not climb (the doorway checks: a shut door must shut the
/// hut) leaves it out.
inline constexpr uint8_t cLadderArea = 5;

/// The path filter of a path that may not climb a ladder.
inline navmesh::PathFilter NoClimbing()
{
    navmesh::PathFilter filter;
    filter.mExcludedAreas = uint64_t(1) << cLadderArea;
    return filter;
}

/// The ladder over the back wall of the hut whose door has the ground points inOutside and inInside
/// (DoorSpec's, out of the doorway and into the room): two-way, its feet on inGenerator's
/// terrain.
navmesh::OffMeshLink MakeHutLadder(const Vec3& inOutside, const Vec3& inInside,
                                   const WorldGenerator& inGenerator);

class HutLadders
{
public:
    HutLadders(const TileStreamer& inStreamer, const WorldGenerator& inGenerator,
               navmesh::TileScheduler& ioHumanScheduler);
    /// Withdraws every ladder it declared.
    ~HutLadders();
    HutLadders(const HutLadders&) = delete;
    HutLadders& operator=(const HutLadders&) = delete;

    /// Ladders for the huts streamed in since the last call, none for those gone.
    void Update();
    uint32_t GetNumLadders() const { return uint32_t(mLadders.size()); }
    uint32_t GetMostLadders() const { return mMostLadders; }
    /// Ladders the scheduler refused (a foot outside its world): none in a good run.
    uint64_t GetNumRefused() const { return mRefused; }
    /// The declared ladders as the human navmesh has them now (TileScheduler::GetOffMeshLinkState).
    struct States
    {
        uint32_t mJoined = 0;
        uint32_t mWaiting = 0; ///< Their tiles not built with them yet, or not loaded
        /// Built into the navmesh but with a foot that joins nothing, or left out: none in a good run
        uint32_t mDead = 0;
    };
    States CountStates() const;

private:
    const TileStreamer& mStreamer;
    const WorldGenerator& mGenerator;
    navmesh::TileScheduler& mScheduler;
    uint64_t mDoorsVersion = 0;
    std::vector<StreamedDoor> mDoors;                          ///< The latest list taken
    std::map<BodyID, navmesh::TileScheduler::LinkID> mLadders; ///< By the hut's door panel
    uint32_t mMostLadders = 0;
    uint64_t mRefused = 0;
};

} // namespace cairn::demo
