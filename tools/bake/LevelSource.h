#pragma once

// LevelSource: where a bake's geometry comes from. The baker asks for the objects near the tiles it is about
// to build and keeps bodies of them only while those tiles are in flight, so a source that makes objects on
// demand (a generated or streamed world) is baked without the whole level ever being in memory.
// Threads: a source is used by the bake's main thread only.

#include "cairn/navmesh/LevelMesh.h"
#include "cairn/physics/math/AABB.h"
#include "cairn/physics/math/Result.h"
#include "cairn/physics/shapes/Shape.h"

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace cairn::bake
{
using namespace cairn::physics;

/// What a body of an object is made of.
struct SourceBody
{
    ShapeRef mShape;
    uint8_t mArea = navmesh::cDefaultArea;
};

/// An object of a level, as a source lists it.
struct SourceObject
{
    uint64_t mKey = 0; ///< Unique and stable; a tile's triangles come in the order of their objects' keys
    AABB mBounds;      ///< Holds every vertex of the object
};

class LevelSource
{
public:
    virtual ~LevelSource() = default;

    /// Bounds of all the geometry (they decide the tiles).
    virtual AABB GetBounds() const = 0;
    /// At least as many as the objects whose bounds one tile's bordered box can overlap (sizes the world).
    virtual uint32_t GetMaxObjectsNear() const = 0;
    /// Objects in the level (the world never needs room for more).
    virtual uint64_t GetNumObjects() const = 0;
    /// Appends the objects whose bounds overlap inBox, each once, in any order.
    virtual void FindObjects(const AABB& inBox, std::vector<SourceObject>& ioObjects) const = 0;
    /// The shape and area of the object with key inKey (one static body). Errors name the object.
    virtual Result<SourceBody> MakeBody(uint64_t inKey) const = 0;
    /// The object in words, for errors ("level.obj: object 'Bridge'").
    virtual std::string Describe(uint64_t inKey) const = 0;
    /// What the bake summary records as its inputs (file names; a generator's name and settings).
    virtual std::vector<std::string> GetInputNames() const = 0;
};

/// OBJ and glTF files, loaded whole (a level file is in memory once anyway) and split into parts (an object's
/// triangles of one area, navmesh::SplitIntoParts); keys are the parts' order. A grid of cells finds the
/// parts near a box.
class FileLevelSource final : public LevelSource
{
public:
    /// Errors: the loaders' (file and line or element), a bad area mapping.
    static Result<std::unique_ptr<FileLevelSource>> Load(const std::vector<std::string>& inPaths,
                                                         const navmesh::AreaMapping& inAreas,
                                                         float inCellSize,
                                                         const navmesh::LevelLoadLimits& inLimits = {});

    AABB GetBounds() const override { return mBounds; }
    uint32_t GetMaxObjectsNear() const override { return uint32_t(mParts.size()); }
    uint64_t GetNumObjects() const override { return mParts.size(); }
    void FindObjects(const AABB& inBox, std::vector<SourceObject>& ioObjects) const override;
    Result<SourceBody> MakeBody(uint64_t inKey) const override;
    std::string Describe(uint64_t inKey) const override;
    std::vector<std::string> GetInputNames() const override { return mPaths; }

private:
    struct Part
    {
        std::string mWhere; ///< File and object
        SourceBody mBody;
        AABB mBounds;
    };
    /// Cells spanned on x and z (inclusive), clamped to +-2^30.
    struct CellRange
    {
        int64_t mX0, mX1, mZ0, mZ1;
    };
    CellRange CellsOf(const AABB& inBox) const;
    static uint64_t CellKey(int64_t inX, int64_t inZ)
    {
        return uint64_t(uint32_t(inX)) << 32 | uint32_t(inZ);
    }
    static constexpr int64_t cMaxCellsPerPart = 64; ///< Parts over more cells are in mLargeParts

    std::vector<std::string> mPaths;
    std::vector<Part> mParts;
    AABB mBounds;
    float mCellSize = 1.0f;
    std::unordered_map<uint64_t, std::vector<uint32_t>> mCells; ///< Cell -> parts whose bounds touch it
    std::vector<uint32_t> mLargeParts;   ///< Parts over more than cMaxCellsPerPart cells
    mutable std::vector<uint32_t> mSeen; ///< FindObjects' dedup stamps, per part
    mutable uint32_t mStamp = 0;
};

} // namespace cairn::bake
