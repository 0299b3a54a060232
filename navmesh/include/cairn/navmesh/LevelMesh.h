#pragma once

// Level meshes for the navmesh: Wavefront OBJ (Recast's demo meshes) read with tinyobjloader, and glTF 2.0
// read with tinygltf: vertices, triangles, the objects they belong to and their materials' names (a level's
// area types come from those, see AreaMapping). Plain functions, any thread.

#include "cairn/navmesh/TileGeometry.h"
#include "cairn/physics/math/AABB.h"
#include "cairn/physics/math/Result.h"

#include <array>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace cairn::navmesh
{
using namespace cairn::physics;

/// A named part of a level file: an OBJ object or group (`o`, `g`), a glTF node with a mesh.
struct MeshObject
{
    std::string mName;
    uint32_t mFirstTriangle = 0; ///< Its triangles are [first, first + count) of IndexedMesh::mTriangles
    uint32_t mNumTriangles = 0;
};

struct IndexedMesh
{
    static constexpr uint32_t cNoMaterial = 0xffffffffu;

    std::vector<Vec3> mVertices;
    std::vector<std::array<uint32_t, 3>> mTriangles;
    std::vector<MeshObject> mObjects;         ///< In triangle order, covering every triangle once
    std::vector<std::string> mMaterials;      ///< Names as the file gives them (OBJ `usemtl`, glTF materials)
    std::vector<uint32_t> mTriangleMaterials; ///< Per triangle: index into mMaterials, or cNoMaterial

    AABB GetBounds() const;
    /// Every triangle, as a tile build takes them, with area inArea.
    TileGeometry ToTileGeometry(uint8_t inArea = cDefaultArea) const;
    /// Ok, or an InvalidArgument error naming the first triangle whose vertex index is past mVertices or the
    /// first object whose triangles run past mTriangles. The loaders make only valid meshes; a mesh built by
    /// hand is checked where it is used (ExtractTriangles, SplitIntoParts).
    Status Validate() const;
    /// The triangles inTriangles (indices into mTriangles) as a mesh of their own, holding only the vertices
    /// they use, in first-use order; no objects or materials. Errors: a triangle index past mTriangles, or a
    /// vertex index past mVertices (InvalidArgument).
    Result<IndexedMesh> ExtractTriangles(std::span<const uint32_t> inTriangles) const;
    /// The name of triangle inTriangle's material, or an empty string when it has none.
    const std::string& GetMaterialName(uint32_t inTriangle) const;
};

/// Navmesh area ids of materials, by name: how a level's floors become roads, grass or water for the path
/// query's costs. Materials it does not name (and triangles without one) get mDefaultArea.
struct AreaMapping
{
    uint8_t mDefaultArea = cDefaultArea;
    std::map<std::string, uint8_t> mMaterialAreas; ///< Area ids up to cMaxAreaId

    uint8_t GetArea(const std::string& inMaterial) const;
    /// Errors: an area id above cMaxAreaId.
    Status Validate() const;
};

/// One static body's worth of a level file: an object's triangles of one area.
struct LevelPart
{
    std::string mName; ///< The object's name
    uint8_t mArea = cDefaultArea;
    IndexedMesh mMesh; ///< Only the vertices its triangles use
};

/// Splits a level mesh into parts: each object, and within it each area that inAreas gives its materials,
/// in the order of the objects and then of each area's first triangle. A mesh without objects is one.
/// Errors: an invalid mesh (IndexedMesh::Validate).
Result<std::vector<LevelPart>> SplitIntoParts(const IndexedMesh& inMesh, const AreaMapping& inAreas);

/// What a level file may make a loader do: work and memory follow the file's size, and a hostile file (a
/// node graph that instances one mesh 2^40 times, JSON nested 100,000 deep) is refused with the name of the
/// limit it broke rather than exhausting the machine. The defaults take any real level.
struct LevelLoadLimits
{
    uint64_t mMaxFileBytes = 4ull << 30; ///< The level file, and each file a glTF reads beside it
    uint32_t mMaxNesting = 64;           ///< JSON arrays and objects inside each other (glTF)
    uint32_t mMaxNodeDepth = 64;         ///< glTF nodes under each other
    uint64_t mMaxTriangles = 1ull << 27; ///< In the whole level, each instance of a mesh counted
    uint64_t mMaxVertices = 1ull << 27;
    /// glTF buffers come from inline data: URIs, the .glb itself or files in the level's folder (and below):
    /// a level must not read /etc/passwd or ../other-level. True lifts the folder rule.
    bool mAllowFilesOutsideFolder = false;
};

/// Errors: IOError when the file cannot be read; ParseError for a malformed file (bad numbers or indices),
/// non-finite or out-of-range coordinates, a mesh without triangles, or a limit of inLimits exceeded.
Result<IndexedMesh> LoadObjMesh(const std::string& inPath, const LevelLoadLimits& inLimits = {});

/// glTF 2.0 (.gltf with its buffers, or .glb), read with tinygltf (Debian's libtinygltf-dev): the triangles
/// of every mesh of the default scene (or of every node when there is none), placed by their nodes'
/// transforms. Images are never decoded (a navmesh has no use for them). Errors name the file and the element
/// (meshes[i].primitives[j], accessors[k]) or limit that is wrong; a node reached twice is an error (glTF's
/// nodes form trees, and a graph that shares nodes grows exponentially).
Result<IndexedMesh> LoadGltfMesh(const std::string& inPath, const LevelLoadLimits& inLimits = {});

/// OBJ or glTF by the file's extension (.obj, .gltf, .glb, in any case).
Result<IndexedMesh> LoadLevelMesh(const std::string& inPath, const LevelLoadLimits& inLimits = {});

} // namespace cairn::navmesh
