#pragma once

// Level meshes for the navmesh: Wavefront OBJ (Recast's demo meshes) read with tinyobjloader, and glTF 2.0
// read with tinygltf; vertices and triangles only (polygons split into fans, materials ignored). Plain
// functions, any thread.

#include "cairn/navmesh/TileGeometry.h"
#include "cairn/physics/math/AABB.h"
#include "cairn/physics/math/Result.h"

#include <array>
#include <string>
#include <vector>

namespace cairn::navmesh
{

struct IndexedMesh
{
    std::vector<Vec3> mVertices;
    std::vector<std::array<uint32_t, 3>> mTriangles;

    AABB GetBounds() const;
    /// Every triangle, as a tile build takes them, with area inArea.
    TileGeometry ToTileGeometry(uint8_t inArea = cDefaultArea) const;
};

/// Errors: IOError when the file cannot be read; ParseError for a malformed file (bad numbers or indices),
/// non-finite or out-of-range coordinates, or a mesh without triangles.
Result<IndexedMesh> LoadObjMesh(const std::string& inPath);

/// glTF 2.0 (.gltf with its buffers, or .glb), read with tinygltf (Debian's libtinygltf-dev): the triangles
/// of every mesh of the default scene (or of every node when there is none), placed by their nodes'
/// transforms. Errors name the file and the element (meshes[i].primitives[j], accessors[k]) that is wrong.
Result<IndexedMesh> LoadGltfMesh(const std::string& inPath);

/// OBJ or glTF by the file's extension (.obj, .gltf, .glb).
Result<IndexedMesh> LoadLevelMesh(const std::string& inPath);

} // namespace cairn::navmesh
