#pragma once

// WorldGenerator: the deterministic open world of the streaming demo. Each world tile is generated on demand
// from the seed and the tile coordinates alone: a height-field terrain, static props (boxes, rock hulls,
// ramps, arches in clusters with walkable gaps between them) and, for high-LOD tiles, dynamic crates, crate
// stacks and debris. The player walks a fixed path along +x and the props keep a corridor around it clear.
//
// Threads: every const method may be called from any number of threads at once. The constructor creates all
// shared shapes (immutable, shared read-only through ShapeRef); afterwards nothing in the generator changes,
// and each call works on its own locals. Results are bit-identical for the same settings on any thread and,
// as they use only integer hashing and IEEE float arithmetic (no <random> distributions, no libm
// trigonometry), on any platform that does not contract float operations into FMAs.
//
// Buildings (Buildings.h: huts with a hinged door) are placed first, from a random stream of their own, so
// that the props keep out of them; with mBuildingsPerTile 0 a tile's props are what they were before huts.

#include "Buildings.h"
#include "cairn/physics/body/BodyCreationSettings.h"

#include <compare>
#include <cstdint>
#include <vector>

namespace cairn::demo
{
using namespace cairn::physics;

/// A world tile of the open world (64 m by default), on the x-z plane:
/// tile (x, z) covers [x*size, (x+1)*size).
struct WorldTile
{
    int32_t mX = 0;
    int32_t mZ = 0;
    auto operator<=>(const WorldTile&) const = default;
};

struct WorldSettings
{
    uint64_t mSeed = 1;
    float mTileSize = 64.0f;   ///< m; rounded to whole metres in [8, 1024] (the height samples are 1 m apart)
    int mPropsPerTile = 700;   ///< Static props on each tile (boxes, convex hulls, small meshes)
    int mDynamicPerTile = 110; ///< Dynamic bodies on a high-LOD tile: crates, stacks, debris
    float mPlayerSpeed = 8.0f; ///< m/s along the player path
    int mBuildingsPerTile = 2; ///< Huts with a door (fewer where the tile has no flat, free room for one)
};

struct TileContent
{
    BodyCreationSettings mTerrain;              ///< A static height field covering the tile
    std::vector<BodyCreationSettings> mProps;   ///< Static: the huts' walls, then the other props
    std::vector<DoorSpec> mDoors;               ///< One per hut, at every LOD
    std::vector<BodyCreationSettings> mDynamic; ///< Dynamic, above the ground, asleep-ready
};

class WorldGenerator
{
public:
    /// Out-of-range settings are clamped (see GetSettings); creates the shared shapes (about 1 ms).
    explicit WorldGenerator(const WorldSettings& inSettings);

    /// The settings in use, after clamping.
    const WorldSettings& GetSettings() const { return mSettings; }

    /// The same tile and seed always give the same content, bit for bit, on any thread (const, no shared
    /// mutable state). Props and terrain do not depend on inWithDynamic. A 64 m tile holds about 1000 props
    /// with the walking gaps between clusters: asking for more gives fewer, and the tiles that the player
    /// path crosses get a few percent fewer. Tiles beyond about 15000 tiles from the origin lie past the
    /// engine's 1e6 m limit: their bodies are generated but the engine refuses them.
    TileContent GenerateTile(const WorldTile& inTile, bool inWithDynamic) const;

    /// Terrain height at a world point (the same surface the height fields have, exactly at samples, and on
    /// the same triangles between them). 0 for NaN or infinite input.
    float GetTerrainHeight(float inX, float inZ) const;

    /// The player's position on its path at inSeconds: starts near the world origin tile centre and crosses
    /// the world along +x with a gentle sine in z, on the terrain surface (y = terrain height).
    Vec3 GetPlayerPosition(float inSeconds) const;

    WorldTile TileAt(float inX, float inZ) const;

private:
    /// A rock: a convex hull made once and placed many times.
    struct Rock
    {
        ShapeRef mShape;
        float mBottom = 0.0f; ///< Lowest local y of the hull
        float mRadius = 0.0f; ///< Largest x-z distance of a hull vertex from the local origin
    };

    /// Everything one GenerateTile call works on (defined in the .cpp file): heights, the footprint grid.
    struct TileContext;
    /// A prop or dynamic body being considered, before the checks accept it.
    struct Candidate;

    /// Height of the global sample (inX, inZ): the world point (inX * 1 m, inZ * 1 m).
    float SampleHeight(int64_t inX, int64_t inZ) const;
    /// The z of the player path at world x.
    double PathZ(double inX) const;
    /// True when a footprint circle (tile-local centre, radius) keeps clear of the player corridor.
    bool IsClearOfPath(const TileContext& inContext, float inX, float inZ, float inRadius) const;
    /// The shared box shape of full sizes cBoxSizes[inX], [inY], [inZ].
    const ShapeRef& GetBox(int inX, int inY, int inZ) const;

    /// Huts first, from a stream of their own (inTileSeed's): their footprints keep the props out.
    void AddBuildings(TileContext& ioContext, uint64_t inTileSeed,
                      std::vector<BodyCreationSettings>& outWalls, std::vector<DoorSpec>& outDoors) const;
    void AddProps(TileContext& ioContext, std::vector<BodyCreationSettings>& outProps) const;
    void AddDynamic(TileContext& ioContext, std::vector<BodyCreationSettings>& outDynamic) const;
    /// One cluster of props around (inX, inZ) (tile-local), appended to ioCandidates.
    void MakeRubble(TileContext& ioContext, float inX, float inZ, std::vector<Candidate>& ioCandidates) const;
    void MakePile(TileContext& ioContext, float inX, float inZ, std::vector<Candidate>& ioCandidates) const;
    void MakeWall(TileContext& ioContext, float inX, float inZ, std::vector<Candidate>& ioCandidates) const;
    void MakeRocks(TileContext& ioContext, float inX, float inZ, std::vector<Candidate>& ioCandidates) const;
    void MakeRamp(TileContext& ioContext, float inX, float inZ, std::vector<Candidate>& ioCandidates) const;
    void MakeArch(TileContext& ioContext, float inX, float inZ, std::vector<Candidate>& ioCandidates) const;

    WorldSettings mSettings;
    uint64_t mSeedHash = 0;       ///< The seed, mixed once
    std::vector<ShapeRef> mBoxes; ///< Every combination of cBoxSizes, index x + n * (y + n * z)
    std::vector<Rock> mRocks;     ///< A handful of hull shapes
    ShapeRef mRamp;               ///< A wedge mesh
    ShapeRef mArch;               ///< A round arch mesh on two legs
    BuildingShapes mBuildingShapes;
    std::vector<double> mPathArcs; ///< Arc length of the path from the start of a sine period, per sample
};

} // namespace cairn::demo
