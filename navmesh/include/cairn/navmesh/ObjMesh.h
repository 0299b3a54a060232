#pragma once

// Wavefront OBJ level meshes (Recast's demo meshes, a baker's input), read with tinyobjloader: vertices and
// triangles only (polygons are split into fans, materials ignored). Plain functions, any thread.

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

} // namespace cairn::navmesh
