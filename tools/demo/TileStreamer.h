#pragma once

// TileStreamer: streams the open world's tiles in and out of the physics world on a loading thread of its
// own, as a game's streaming system does. The main thread only says where the player is (SetFocus: a
// try-lock, it never waits); the loading thread (at a lower OS priority) generates a tile's bodies, creates
// them, prepares their broad-phase add off the main thread and finalizes it (an O(1) link into the broad
// phase), and removes tiles that left the collision radius. Tiles within one tile of the player are high-LOD
// and also get dynamic bodies (crates, stacks, debris; created asleep), removed again when the tile drops
// back to medium LOD. Huts' doors (Buildings.h) come with the tile's statics at every LOD: a dynamic panel
// and its hinge to the world each, removed with the tile (the hinge first).
//
// Threads: SetFocus, GetStats, IsSettled, TakeDoorsIfChanged from any thread (mMutex); everything else
// happens on the loading thread, which owns mTiles. The physics world is used through BodyInterface, which
// may be called while the world steps (adds wait for the step only on the loading thread).

#include "WorldGenerator.h"
#include "cairn/physics/PhysicsSystem.h"

#include <atomic>
#include <condition_variable>
#include <map>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

namespace cairn::demo
{
using namespace cairn::physics;

/// A door in the world, as the loading thread made it: for the main thread's Doors.
struct StreamedDoor
{
    BodyID mPanel;
    ConstraintID mHinge;
    Vec3 mOutside = Vec3::Zero(); ///< DoorSpec's: ground points either side of the doorway
    Vec3 mInside = Vec3::Zero();
    float mPeriod = 0.0f; ///< DoorSpec's timer, s
    float mPhase = 0.0f;
};

class TileStreamer
{
public:
    struct Stats
    {
        std::vector<double> mStreamInMs;   ///< Per tile: generate, create, prepare and finalize
        std::vector<double> mStreamLinkMs; ///< Per batch: the finalize alone
        std::vector<double> mStreamOutMs;  ///< Per tile: remove and destroy
        uint32_t mTilesIn = 0;
        uint32_t mTilesOut = 0;
        uint32_t mStaticBodies = 0; ///< In the world now, from this streamer
        uint32_t mDynamicBodies = 0;
        uint32_t mStaticPeak = 0;
        uint32_t mDynamicPeak = 0;
        std::vector<std::string> mErrors;
    };

    /// inCollisionRadius: tiles whose centre is within this many tiles of the player's tile get collision.
    TileStreamer(PhysicsSystem& ioPhysics, const WorldGenerator& inGenerator, float inCollisionRadius = 3.0f);
    /// Stops the loading thread (the world keeps what is loaded; see UnloadAll).
    ~TileStreamer();
    TileStreamer(const TileStreamer&) = delete;
    TileStreamer& operator=(const TileStreamer&) = delete;

    /// Where the player is and where it will be soon: tiles around both are wanted. Never waits: when the
    /// loading thread holds the lock, this focus is skipped (call it every frame).
    void SetFocus(const Vec3& inPlayer, const Vec3& inAhead);
    /// True when every wanted tile is loaded at the right LOD and nothing else is.
    bool IsSettled() const;
    Stats GetStats() const;
    /// Tiles with collision now (loaded), for checks.
    std::vector<WorldTile> GetLoadedTiles() const;

    /// Removes every streamed body and stops; then checks that each body it made is gone and that no other
    /// body appeared. Returns the number of bodies lost or duplicated (0 when all is well).
    uint32_t UnloadAllAndCheck();
    /// While running: bodies the streamer believes are in the world that the world does not have (lost), plus
    /// bodies the world has beyond those (duplicated or leaked). Call when settled, between frames.
    uint32_t CountLostOrDuplicated() const;
    /// Whether inBody is a terrain body (the wall checks ignore the ground).
    bool IsTerrain(const BodyID& inBody) const;
    /// The doors in the world now, when they changed since ioVersion (updated); false, with outDoors as it
    /// was, when they did not or when the loading thread holds the lock (the caller never waits: it asks
    /// again next frame). A door may be gone by the time its caller uses it: its ids go stale.
    bool TakeDoorsIfChanged(uint64_t& ioVersion, std::vector<StreamedDoor>& outDoors) const;

private:
    struct LoadedTile
    {
        std::vector<BodyID> mStatic;  ///< Terrain first, then props
        std::vector<BodyID> mDynamic; ///< Empty unless high-LOD
        std::vector<StreamedDoor> mDoors;
    };

    void ThreadMain();
    /// The tiles wanted for a focus, with true for high LOD.
    std::map<WorldTile, bool> WantedTiles(const Vec3& inPlayer, const Vec3& inAhead) const;
    void LoadTile(const WorldTile& inTile, LoadedTile& outTile);
    void AddDynamic(const WorldTile& inTile, LoadedTile& ioTile);
    void RemoveBodies(std::vector<BodyID>& ioBodies);
    /// Creates the doors' panels as one batch and hinges each to the world.
    void AddDoors(std::vector<DoorSpec>& ioDoors, LoadedTile& ioTile);
    /// Removes the hinges, then the panels.
    void RemoveDoors(LoadedTile& ioTile);
    /// The loaded tiles' doors into mDoors for the main thread, a new version; with mMutex held.
    void PublishDoorsLocked();
    /// Creates, prepares and finalizes a batch; false (with an error noted) on failure.
    bool AddBatch(const std::vector<BodyCreationSettings>& inSettings, Activation inActivation,
                  std::vector<BodyID>& outIDs);
    void NoteError(std::string inError);

    PhysicsSystem& mPhysics;
    const WorldGenerator& mGenerator;
    const float mCollisionRadius;
    const uint32_t mBodiesBefore; ///< Bodies in the world before streaming started (not ours)

    mutable std::mutex mMutex;
    std::condition_variable mWake;
    bool mStop = false;
    bool mHasFocus = false;
    Vec3 mPlayer = Vec3::Zero();
    Vec3 mAhead = Vec3::Zero();
    bool mSettled = false;
    Stats mStats;
    std::map<WorldTile, bool> mLoadedLod; ///< Copy of the loaded tiles and their LOD, for other threads
    std::vector<StreamedDoor> mDoors;     ///< Copy of the loaded tiles' doors, for other threads
    uint64_t mDoorsVersion = 1;           ///< Changes with mDoors

    std::map<WorldTile, LoadedTile> mTiles; ///< Loading thread only (and UnloadAllAndCheck after it stopped)
    mutable std::mutex mTerrainMutex;
    std::set<BodyID> mTerrain; ///< Guarded by mTerrainMutex
    std::thread mThread;
};

} // namespace cairn::demo
