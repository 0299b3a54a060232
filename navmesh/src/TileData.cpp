#include "cairn/navmesh/TileData.h"

#include "cairn/physics/math/Math.h"

#include <DetourCommon.h>
#include <algorithm>
#include <cmath>
#include <cstring>

namespace cairn::navmesh
{
using namespace cairn::physics;

namespace
{
/// Reads element inIndex of an array of T at inOffset of inData (unaligned-safe).
template <class T> T ReadAt(std::span<const unsigned char> inData, size_t inOffset, size_t inIndex)
{
    T value;
    std::memcpy(&value, inData.data() + inOffset + inIndex * sizeof(T), sizeof(T));
    return value;
}

/// A coordinate Detour's arithmetic cannot turn into infinity or NaN: distances and path costs between two
/// such stay finite.
bool IsSaneCoordinate(float inValue)
{
    return std::abs(inValue) <= cMaxWorldCoordinate; // False for NaN too
}

/// Detour's bits for a count: log2 of the next power of two.
int BitsFor(unsigned inCount)
{
    int bits = 0;
    while (bits < 32 && (1ull << bits) < inCount)
        ++bits;
    return bits;
}
} // namespace

std::string CheckTileData(std::span<const unsigned char> inData)
{
    if (inData.size() < sizeof(dtMeshHeader)) return "shorter than a Detour tile header";
    const dtMeshHeader h = ReadAt<dtMeshHeader>(inData, 0, 0);
    if (h.magic != DT_NAVMESH_MAGIC || h.version != DT_NAVMESH_VERSION) return "not Detour tile data";
    constexpr int cMaxCount = 1 << 20;
    for (const int count : {h.vertCount, h.polyCount, h.maxLinkCount, h.detailMeshCount, h.detailVertCount,
                            h.detailTriCount, h.bvNodeCount, h.offMeshConCount})
        if (count < 0 || count > cMaxCount) return "a section count is negative or over 2^20";
    // addTile threads the links into a free list and ends it at link maxLinkCount - 1: with none it writes
    // before the section (every real tile has a link per polygon edge at least)
    if (h.maxLinkCount < 1) return "it has no room for links";
    // Detour measures path costs between these positions: a NaN cost never compares greater, so A* reopens
    // nodes for ever, and infinite coordinates make NaN by subtraction
    if (!IsSaneCoordinate(h.bmin[0]) || !IsSaneCoordinate(h.bmin[1]) || !IsSaneCoordinate(h.bmin[2]) ||
        !IsSaneCoordinate(h.bmax[0]) || !IsSaneCoordinate(h.bmax[1]) || !IsSaneCoordinate(h.bmax[2]))
        return "its bounds are not finite or beyond " + std::to_string(int(cMaxWorldCoordinate)) + " m";
    if (!(h.bmin[0] <= h.bmax[0] && h.bmin[1] <= h.bmax[1] && h.bmin[2] <= h.bmax[2]))
        return "its bounds are inverted";
    for (const float length : {h.walkableHeight, h.walkableRadius, h.walkableClimb})
        if (!(length >= 0.0f && length <= cMaxWorldCoordinate))
            return "an agent size is negative or not finite";
    // The BV tree's boxes are the tile's extent times this factor in 16 bits, and queries quantize by it
    if (h.bvNodeCount > 0)
        for (int k = 0; k < 3; ++k)
            if (!(h.bvQuantFactor > 0.0f && (h.bmax[k] - h.bmin[k]) * h.bvQuantFactor <= 65535.0f))
                return "its bounding-volume quantization does not fit 16 bits";
    if (h.offMeshBase < 0 || h.offMeshBase > h.polyCount) return "the off-mesh base is outside the polygons";
    if (h.offMeshConCount > h.polyCount - h.offMeshBase)
        return "more off-mesh connections than polygons from the off-mesh base";
    // The sections in Detour's order, each padded to 4 bytes (dtNavMesh::addTile)
    size_t offset = size_t(dtAlign4(int(sizeof(dtMeshHeader))));
    auto section = [&](size_t inElementSize, int inCount)
    {
        const size_t start = offset;
        offset += (inElementSize * size_t(inCount) + 3) & ~size_t(3);
        return start;
    };
    const size_t verts = section(3 * sizeof(float), h.vertCount);
    const size_t polys = section(sizeof(dtPoly), h.polyCount);
    section(sizeof(dtLink), h.maxLinkCount);
    const size_t details = section(sizeof(dtPolyDetail), h.detailMeshCount);
    const size_t detailVerts = section(3 * sizeof(float), h.detailVertCount);
    const size_t detailTris = section(4, h.detailTriCount);
    const size_t bvNodes = section(sizeof(dtBVNode), h.bvNodeCount);
    const size_t offMesh = section(sizeof(dtOffMeshConnection), h.offMeshConCount);
    if (offset > inData.size())
        return "its sections need " + std::to_string(offset) + " bytes, it has " +
               std::to_string(inData.size());
    for (int i = 0; i < 3 * h.vertCount; ++i)
        if (!IsSaneCoordinate(ReadAt<float>(inData, verts, size_t(i))))
            return "vertex " + std::to_string(i / 3) + " is not finite or out of range";
    for (int i = 0; i < 3 * h.detailVertCount; ++i)
        if (!IsSaneCoordinate(ReadAt<float>(inData, detailVerts, size_t(i))))
            return "detail vertex " + std::to_string(i / 3) + " is not finite or out of range";
    for (int i = 0; i < h.polyCount; ++i)
    {
        const dtPoly poly = ReadAt<dtPoly>(inData, polys, size_t(i));
        const bool offMeshPoly = poly.getType() == DT_POLYTYPE_OFFMESH_CONNECTION;
        // Detour finds an off-mesh polygon's connection at index i - offMeshBase, unchecked
        if (offMeshPoly && (i < h.offMeshBase || i - h.offMeshBase >= h.offMeshConCount))
            return "off-mesh polygon " + std::to_string(i) + " has no off-mesh connection";
        if (poly.vertCount > DT_VERTS_PER_POLYGON || poly.vertCount < (offMeshPoly ? 2 : 3))
            return "polygon " + std::to_string(i) + " has " + std::to_string(poly.vertCount) + " vertices";
        for (int j = 0; j < poly.vertCount; ++j)
        {
            if (poly.verts[j] >= h.vertCount)
                return "polygon " + std::to_string(i) + " names a missing vertex";
            const unsigned short neighbour = poly.neis[j];
            if (neighbour != 0 && (neighbour & DT_EXT_LINK) == 0 && neighbour - 1 >= h.polyCount)
                return "polygon " + std::to_string(i) + " names a missing neighbour";
        }
        if (offMeshPoly) continue;
        if (i >= h.detailMeshCount) return "polygon " + std::to_string(i) + " has no detail mesh";
        const dtPolyDetail detail = ReadAt<dtPolyDetail>(inData, details, size_t(i));
        if (size_t(detail.vertBase) + detail.vertCount > size_t(h.detailVertCount) ||
            size_t(detail.triBase) + detail.triCount > size_t(h.detailTriCount))
            return "the detail mesh of polygon " + std::to_string(i) + " is outside the detail arrays";
        // Detour's closest point on a polygon walks its detail triangles' boundary edges and reads the
        // nearest one it found without checking that there was one: a polygon needs a triangle, and a
        // triangle an edge flagged as boundary
        constexpr unsigned char cAnyBoundaryEdge =
            DT_DETAIL_EDGE_BOUNDARY | DT_DETAIL_EDGE_BOUNDARY << 2 | DT_DETAIL_EDGE_BOUNDARY << 4;
        bool boundary = false;
        for (int t = 0; t < detail.triCount; ++t)
        {
            const size_t triangle = (size_t(detail.triBase) + size_t(t)) * 4;
            for (int k = 0; k < 3; ++k)
                if (ReadAt<unsigned char>(inData, detailTris, triangle + size_t(k)) >=
                    poly.vertCount + detail.vertCount)
                    return "a detail triangle of polygon " + std::to_string(i) + " names a missing vertex";
            boundary =
                boundary || (ReadAt<unsigned char>(inData, detailTris, triangle + 3) & cAnyBoundaryEdge) != 0;
        }
        if (!boundary)
            return "the detail mesh of polygon " + std::to_string(i) + " has no triangle on its boundary";
    }
    // Detour's raycast walks from polygon to polygon through the links until the ray leaves, with no bound: a
    // polygon that is its own neighbour (the fuzzer: one changed byte), a neighbour that does not share the
    // edge back, or a polygon that is not convex with an area sent it round for ever
    auto vertex = [&](unsigned short inIndex, int inAxis)
    { return double(ReadAt<float>(inData, verts, size_t(inIndex) * 3 + size_t(inAxis))); };
    for (int i = 0; i < h.polyCount; ++i)
    {
        const dtPoly poly = ReadAt<dtPoly>(inData, polys, size_t(i));
        if (poly.getType() == DT_POLYTYPE_OFFMESH_CONNECTION) continue;
        const int n = poly.vertCount;
        double area = 0.0;
        bool turnsLeft = false, turnsRight = false;
        for (int j = 0; j < n; ++j)
        {
            const unsigned short a = poly.verts[j], b = poly.verts[(j + 1) % n], c = poly.verts[(j + 2) % n];
            const double turn = (vertex(b, 0) - vertex(a, 0)) * (vertex(c, 2) - vertex(b, 2)) -
                                (vertex(b, 2) - vertex(a, 2)) * (vertex(c, 0) - vertex(b, 0));
            turnsLeft = turnsLeft || turn > 0.0;
            turnsRight = turnsRight || turn < 0.0;
            area += vertex(a, 0) * vertex(b, 2) - vertex(b, 0) * vertex(a, 2);
            const unsigned short neighbour = poly.neis[j];
            if (neighbour == 0 || (neighbour & DT_EXT_LINK) != 0) continue;
            const int other = neighbour - 1;
            if (other == i) return "polygon " + std::to_string(i) + " is its own neighbour";
            const dtPoly back = ReadAt<dtPoly>(inData, polys, size_t(other));
            bool shared = false;
            for (int k = 0; k < back.vertCount && back.getType() != DT_POLYTYPE_OFFMESH_CONNECTION; ++k)
                shared = shared || (back.neis[k] == i + 1 && back.verts[k] == b &&
                                    back.verts[(k + 1) % back.vertCount] == a);
            if (!shared)
                return "polygons " + std::to_string(i) + " and " + std::to_string(other) +
                       " are neighbours without sharing the edge both ways";
        }
        if (turnsLeft && turnsRight) return "polygon " + std::to_string(i) + " is not convex";
        if (area == 0.0) return "polygon " + std::to_string(i) + " has no area";
    }
    for (int i = 0; i < h.bvNodeCount; ++i)
    {
        const int index = ReadAt<dtBVNode>(inData, bvNodes, size_t(i)).i;
        if (index >= h.polyCount || (index < 0 && (index == INT32_MIN || -index > h.bvNodeCount - i)))
            return "bounding-volume node " + std::to_string(i) + " points outside the tree";
    }
    for (int i = 0; i < h.offMeshConCount; ++i)
    {
        const dtOffMeshConnection connection = ReadAt<dtOffMeshConnection>(inData, offMesh, size_t(i));
        if (connection.poly >= h.polyCount)
            return "off-mesh connection " + std::to_string(i) + " names a missing polygon";
        bool sane = connection.rad >= 0.0f && connection.rad <= cMaxWorldCoordinate;
        for (const float coordinate : connection.pos)
            sane = sane && IsSaneCoordinate(coordinate);
        if (!sane) return "off-mesh connection " + std::to_string(i) + " is not finite or out of range";
    }
    return "";
}

namespace
{
/// The smallest tile side a navmesh may have, m (a tile of 16 cells of 2 cm)
constexpr float cMinTileSize = 0.25f;
} // namespace

std::string CheckNavMeshParams(const dtNavMeshParams& inParams)
{
    if (!IsSaneCoordinate(inParams.orig[0]) || !IsSaneCoordinate(inParams.orig[1]) ||
        !IsSaneCoordinate(inParams.orig[2]))
        return "the origin is not finite or beyond " + std::to_string(int(cMaxWorldCoordinate)) + " m";
    // At least cMinTileSize: Detour's polygon queries visit every tile slot their box covers, and a fuzzed
    // file with tiles a hair wide made one search box of a few metres cover billions (a query ran for
    // seconds)
    if (!(inParams.tileWidth >= cMinTileSize && inParams.tileWidth <= cMaxWorldCoordinate &&
          inParams.tileHeight >= cMinTileSize && inParams.tileHeight <= cMaxWorldCoordinate))
        return "the tile size is not a finite length from " + std::to_string(cMinTileSize) + " m";
    if (inParams.maxTiles < 1 || inParams.maxTiles > cMaxNavMeshTiles)
        return "max tiles " + std::to_string(inParams.maxTiles) + " is not 1 to " +
               std::to_string(cMaxNavMeshTiles);
    if (inParams.maxPolys < 1 || inParams.maxPolys > (1 << 22))
        return "max polygons per tile " + std::to_string(inParams.maxPolys) + " is not 1 to 2^22";
    // Detour's own test of these bits is done in unsigned arithmetic that wraps around and passes
    if (BitsFor(unsigned(inParams.maxTiles)) + BitsFor(unsigned(inParams.maxPolys)) > 22)
        return "max tiles and max polygons leave fewer than 10 bits of salt in a 32-bit polygon reference";
    return "";
}

std::string CheckTileFitsParams(std::span<const unsigned char> inData, const dtNavMeshParams& inParams)
{
    const dtMeshHeader h = ReadAt<dtMeshHeader>(inData, 0, 0);
    // Polygon indices past the polygon bits spill into the tile bits: a link would name another tile's
    // polygon
    if (h.polyCount > int(1u << BitsFor(unsigned(inParams.maxPolys))))
        return std::to_string(h.polyCount) + " polygons, over the " + std::to_string(inParams.maxPolys) +
               " the navmesh's polygon references hold";
    return "";
}

Result<dtNavMeshParams> MakeNavMeshParams(const TileGrid& inGrid, int inMaxTiles)
{
    if (inMaxTiles < 1 || inMaxTiles > cMaxNavMeshTiles)
        return MakeError(ErrorCode::InvalidArgument, "navmesh: max tiles must be 1 to 2^20");
    // A 32-bit polygon reference holds salt, tile and polygon bits: tiles take what they need, polygons get
    // the rest up to 22 (10 bits of salt, as Detour's samples leave)
    const int tileBits = BitsFor(unsigned(inMaxTiles));
    const int polyBits = std::min(22 - tileBits, 14);
    if (polyBits < 8)
        return MakeError(
            ErrorCode::OutOfCapacity,
            "navmesh: " + std::to_string(inMaxTiles) +
                " tiles leave too few bits of a 32-bit polygon reference for the polygons of a tile");
    dtNavMeshParams params{};
    params.orig[0] = inGrid.GetOriginX();
    params.orig[1] = 0.0f;
    params.orig[2] = inGrid.GetOriginZ();
    params.tileWidth = inGrid.GetTileSize();
    params.tileHeight = inGrid.GetTileSize();
    params.maxTiles = 1 << tileBits;
    params.maxPolys = 1 << polyBits;
    // What a navmesh file must meet, a world made in memory too: tiles narrower than cMinTileSize made one
    // crowd agent's snap to the navmesh visit millions of tile slots (seconds a frame)
    if (const std::string problem = CheckNavMeshParams(params); !problem.empty())
        return MakeError(ErrorCode::InvalidArgument, "navmesh: " + problem);
    return params;
}

} // namespace cairn::navmesh
