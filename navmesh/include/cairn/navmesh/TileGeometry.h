#pragma once

// TileGeometry: the triangles one tile is built from, in world space, as Recast takes them (flat vertex and
// index arrays), each with a navmesh area id. Filled by GeometryCollector (or from a file), read by
// TileBuilder. Plain value type, owned by one tile job at a time.

#include "cairn/physics/math/Math.h"

#include <cstdint>
#include <vector>

namespace cairn::navmesh
{
using namespace cairn::physics;

/// Area ids as bodies carry them (Body::GetNavMeshArea): 0 is the default walkable ground; other values up
/// to cMaxAreaId are the game's own (road, water...), priced by the path query's filter.
inline constexpr uint8_t cDefaultArea = 0;
inline constexpr uint8_t cMaxAreaId = 62;

struct TileGeometry
{
    std::vector<float> mVertices; ///< x, y, z per vertex
    std::vector<int> mTriangles;  ///< 3 vertex indices per triangle, counter-clockwise seen from above
    std::vector<uint8_t> mAreas;  ///< Area id per triangle

    void Clear()
    {
        mVertices.clear();
        mTriangles.clear();
        mAreas.clear();
    }
    int GetNumVertices() const { return int(mVertices.size() / 3); }
    int GetNumTriangles() const { return int(mTriangles.size() / 3); }
    void AddTriangle(const Vec3& inV0, const Vec3& inV1, const Vec3& inV2, uint8_t inArea)
    {
        const int first = GetNumVertices();
        for (const Vec3* v : {&inV0, &inV1, &inV2})
            mVertices.insert(mVertices.end(), {v->x(), v->y(), v->z()});
        mTriangles.insert(mTriangles.end(), {first, first + 1, first + 2});
        mAreas.push_back(inArea);
    }
};

} // namespace cairn::navmesh
