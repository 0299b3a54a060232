#pragma once

// LiveObjects: the static bodies of a bake's objects while tiles that need them are in flight. A tile
// entering the bake acquires the objects near it (a body is made, in one broad-phase batch per tile, for each
// object no tile in flight has yet); a tile leaving releases them (a body goes when its last tile is done).
// So the world holds the objects of the tiles in flight, never the whole level. Threads: the bake's main
// thread only. Tile jobs on other threads read the bodies through the broad phase and body locks, as the
// runtime's tile jobs do; a body is never removed while a tile that acquired it runs.

#include "LevelSource.h"
#include "cairn/physics/PhysicsSystem.h"

#include <unordered_map>
#include <vector>

namespace cairn::bake
{
using namespace cairn::physics;

/// A body of a tile's object.
struct TileObject
{
    uint64_t mKey;
    BodyID mBody;
};

class LiveObjects
{
public:
    LiveObjects(PhysicsSystem& ioPhysics, const LevelSource& inSource)
        : mPhysics(ioPhysics), mSource(inSource)
    {
    }

    /// Bodies for inObjects (each made if no tile holds it yet), in key order. Errors: the source's, or the
    /// world's capacity; then nothing is held.
    Result<std::vector<TileObject>> Acquire(std::vector<SourceObject>& ioObjects);
    /// Gives back what Acquire returned; bodies no tile holds any more leave the world.
    void Release(const std::vector<TileObject>& inObjects);

    uint32_t GetNumLive() const { return uint32_t(mLive.size()); }
    uint32_t GetPeakLive() const { return mPeakLive; }
    uint64_t GetNumMade() const { return mNumMade; } ///< Bodies made in all (an object may come back)

private:
    struct Live
    {
        BodyID mBody;
        uint32_t mTiles = 0; ///< Tiles in flight that hold it
    };
    void Destroy(const BodyID& inBody);

    PhysicsSystem& mPhysics;
    const LevelSource& mSource;
    std::unordered_map<uint64_t, Live> mLive;
    uint32_t mPeakLive = 0;
    uint64_t mNumMade = 0;
};

} // namespace cairn::bake
