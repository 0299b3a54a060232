#pragma once

// GeneratedLevel: a procedural level of any size, for the baker's benchmarks and tests: a grid of square
// cells, each a rolling ground mesh with boxes and ramps standing on it. It holds no objects: an object's
// vertices, triangles and bounds are computed again from the seed, its cell and its index whenever they are
// asked for, so a world 100 times larger costs 100 times the time to bake at about the same peak memory.
// Integer hashing (splitmix64) and float arithmetic only (+, -, *, /, sqrt, floor: no sin, std::hash or
// distributions; no fused multiply-adds), so a seed gives the same level with any compiler and standard
// library that rounds floats the IEEE way. Threads: a LevelSource, used by the bake's main thread; but its
// const methods only read what Create fixed, so they are in fact safe from any number of threads at once.

#include "LevelSource.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace cairn::bake
{
using namespace cairn::physics;

struct GeneratedLevelSettings
{
    uint64_t mSeed = 1;
    uint32_t mCellsX = 4, mCellsZ = 4; ///< World size in cells, from the origin towards +x and +z
    float mCellSize = 32.0f;           ///< m
    uint32_t mPropsPerCell = 24;       ///< Boxes (every 6th a ramp) standing on the ground
};

class GeneratedLevel final : public LevelSource
{
public:
    static constexpr uint32_t cMaxCellsPerSide = 4096;
    static constexpr uint32_t cMaxPropsPerCell = 4000; ///< An object's index in its cell has 16 bits of key
    /// Props shrink to fit their cell: smaller cells would make slivers of them (and crowd a tile)
    static constexpr float cMinCellSize = 1.0f;
    static constexpr float cMaxCellSize = 1000.0f;
    /// GetMaxObjectsNear assumes that no query box is wider (x or z) than this. The baker's are a tile and
    /// its border: 12.8 m + 2 x ~1.2 m with the default profile. A wider box may find more objects than it
    /// says.
    static constexpr float cMaxQueryBoxSide = 64.0f;
    static constexpr uint32_t cMaxObjectsNearLimit = 1u << 20;
    /// A key is (cell << cIndexBits) | index, the cell numbered in rows of x (z * cells in x + x)
    static constexpr uint32_t cIndexBits = 16;

    /// Visits every object once to find the exact bounds (O(world) time, no memory): a tile's height range
    /// comes from them, so the level baked directly and baked from ToObj() must have the same bounds to give
    /// the same tiles. Errors (InvalidArgument): no cells; more than cMaxCellsPerSide cells a side; a cell
    /// size outside [cMinCellSize, cMaxCellSize] or not finite; a side longer than cMaxWorldCoordinate; more
    /// than cMaxPropsPerCell props per cell; more than cMaxObjectsNearLimit objects near a query box.
    static Result<std::unique_ptr<GeneratedLevel>> Create(const GeneratedLevelSettings& inSettings);

    AABB GetBounds() const override { return mBounds; }
    uint32_t GetMaxObjectsNear() const override { return mMaxObjectsNear; }
    uint64_t GetNumObjects() const override
    {
        return uint64_t(mSettings.mCellsX) * mSettings.mCellsZ * (1 + uint64_t(mSettings.mPropsPerCell));
    }
    /// Costs O(cells the box's x/z range touches + their objects), whatever the world's size.
    void FindObjects(const AABB& inBox, std::vector<SourceObject>& ioObjects) const override;
    /// A TriangleMeshShape of MakeObject's part. Errors: MakeObject's, the shape's (with Describe's words).
    Result<SourceBody> MakeBody(uint64_t inKey) const override;
    std::string Describe(uint64_t inKey) const override;
    std::vector<std::string> GetInputNames() const override;

    /// Key of object inIndex (0: the ground, then the props from 1) of cell (inCellX, inCellZ).
    uint64_t MakeKey(uint32_t inCellX, uint32_t inCellZ, uint32_t inIndex) const
    {
        return (uint64_t(inCellZ) * mSettings.mCellsX + inCellX) << cIndexBits | inIndex;
    }
    /// The geometry MakeBody makes a shape of. Ground: "cell_X_Z_ground", 8 x 8 quads; props:
    /// "cell_X_Z_box_I" (12 triangles) or "cell_X_Z_ramp_I" (8 triangles); all of area navmesh::cDefaultArea,
    /// triangles counter-clockwise seen from outside (the ground's from above). Errors (InvalidArgument): a
    /// key no object has.
    Result<navmesh::LevelPart> MakeObject(uint64_t inKey) const;
    const GeneratedLevelSettings& GetSettings() const { return mSettings; }
    /// The whole level as Wavefront OBJ, an `o` per object in key order with its own vertices ("%.9g": floats
    /// read back bit-exact), for tests on small levels: it is as large as the level.
    std::string ToObj() const;

private:
    explicit GeneratedLevel(const GeneratedLevelSettings& inSettings) : mSettings(inSettings) {}

    GeneratedLevelSettings mSettings;
    AABB mBounds;
    uint32_t mMaxObjectsNear = 0;
};

} // namespace cairn::bake
