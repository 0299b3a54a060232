#include "cairn/navmesh/NavMeshFile.h"

#include "cairn/navmesh/PendingFile.h"
#include "cairn/physics/math/Math.h"

#include <DetourAlloc.h>
#include <DetourCommon.h>
#include <DetourNavMesh.h>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <tuple>

namespace cairn::navmesh
{

namespace
{
// Recast's demo (Sample_TileMesh.cpp) defines these; the values are the file format
constexpr int32_t cSetMagic = 'M' << 24 | 'S' << 16 | 'E' << 8 | 'T';
constexpr int32_t cSetVersion = 1;

struct SetHeader
{
    int32_t mMagic;
    int32_t mVersion;
    int32_t mNumTiles;
    dtNavMeshParams mParams;
};

struct TileHeader
{
    dtTileRef mTileRef;
    int32_t mDataSize;
};

/// The tile's coordinates from its Detour header; false if the data is not a Detour tile.
bool ReadTileCoord(const std::vector<unsigned char>& inData, TileCoord& outTile)
{
    if (inData.size() < sizeof(dtMeshHeader)) return false;
    dtMeshHeader header;
    std::memcpy(&header, inData.data(), sizeof(header));
    if (header.magic != DT_NAVMESH_MAGIC || header.version != DT_NAVMESH_VERSION) return false;
    outTile = {header.x, header.y};
    return true;
}

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

void SortTiles(NavMeshFileContents& ioContents)
{
    std::sort(ioContents.mTiles.begin(), ioContents.mTiles.end(),
              [](const NavMeshFileTile& inL, const NavMeshFileTile& inR) { return inL.mTile < inR.mTile; });
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

std::string CheckNavMeshParams(const dtNavMeshParams& inParams)
{
    if (!IsSaneCoordinate(inParams.orig[0]) || !IsSaneCoordinate(inParams.orig[1]) ||
        !IsSaneCoordinate(inParams.orig[2]))
        return "the origin is not finite or beyond " + std::to_string(int(cMaxWorldCoordinate)) + " m";
    if (!(inParams.tileWidth > 0.0f && inParams.tileWidth <= cMaxWorldCoordinate &&
          inParams.tileHeight > 0.0f && inParams.tileHeight <= cMaxWorldCoordinate))
        return "the tile size is not a positive finite length";
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
    return params;
}

NavMeshFileWriter::NavMeshFileWriter(std::string inPath, const dtNavMeshParams& inParams)
    : mPath(std::move(inPath)), mParams(inParams), mFile(mPath)
{
}

NavMeshFileWriter::~NavMeshFileWriter() = default;

Result<std::unique_ptr<NavMeshFileWriter>> NavMeshFileWriter::Create(const std::string& inPath,
                                                                     const dtNavMeshParams& inParams)
{
    if (const std::string problem = CheckNavMeshParams(inParams); !problem.empty())
        return MakeError(ErrorCode::InvalidArgument, inPath + ": the navmesh parameters: " + problem);
    std::unique_ptr<NavMeshFileWriter> writer(new NavMeshFileWriter(inPath, inParams));
    // The references a fresh navmesh gives tiles added in file order: tile slot i, salt 1
    writer->mLayout.reset(dtAllocNavMesh());
    if (writer->mLayout == nullptr || dtStatusFailed(writer->mLayout->init(&inParams)))
        return MakeError(ErrorCode::InvalidArgument, inPath + ": the navmesh parameters are invalid");
    if (Status opened = writer->mFile.GetOpenStatus(); !opened) return opened.GetError();
    // The tile count is written again by Finish, when it is known
    const SetHeader header{cSetMagic, cSetVersion, 0, inParams};
    writer->mFile.Stream().write(reinterpret_cast<const char*>(&header), sizeof(header));
    return writer;
}

Status NavMeshFileWriter::Add(const TileCoord& inTile, std::span<const unsigned char> inData)
{
    if (mCompleted) return MakeError(ErrorCode::InvalidArgument, mPath + ": a tile added after Complete");
    if (mNumTiles > 0 && !(mLastTile < inTile))
        return MakeError(ErrorCode::InvalidArgument,
                         mPath + ": tile (" + std::to_string(inTile.mX) + ", " + std::to_string(inTile.mZ) +
                             ") comes after a later one: tiles go in sorted order");
    if (mNumTiles >= mParams.maxTiles)
        return MakeError(ErrorCode::OutOfCapacity, mPath + ": more tiles than the parameters allow (" +
                                                       std::to_string(mParams.maxTiles) + ")");
    TileCoord fromData;
    const std::vector<unsigned char> header(inData.begin(),
                                            inData.begin() + std::min(inData.size(), sizeof(dtMeshHeader)));
    if (!ReadTileCoord(header, fromData) || !(fromData == inTile))
        return MakeError(ErrorCode::InvalidArgument,
                         mPath + ": the data of tile (" + std::to_string(inTile.mX) + ", " +
                             std::to_string(inTile.mZ) + ") is not a Detour tile at that place");
    const TileHeader tileHeader{mLayout->encodePolyId(1, unsigned(mNumTiles), 0), int32_t(inData.size())};
    mFile.Stream().write(reinterpret_cast<const char*>(&tileHeader), sizeof(tileHeader));
    mFile.Stream().write(reinterpret_cast<const char*>(inData.data()), std::streamsize(inData.size()));
    ++mNumTiles;
    mLastTile = inTile;
    return Status::Ok();
}

Status NavMeshFileWriter::Complete()
{
    if (mCompleted) return Status::Ok();
    mCompleted = true;
    const SetHeader header{cSetMagic, cSetVersion, mNumTiles, mParams};
    mFile.Stream().seekp(0);
    mFile.Stream().write(reinterpret_cast<const char*>(&header), sizeof(header));
    return mFile.Complete();
}

Status NavMeshFileWriter::Commit()
{
    if (Status completed = Complete(); !completed) return completed;
    return mFile.Commit();
}

Status SaveNavMeshFile(const std::string& inPath, NavMeshFileContents inContents)
{
    SortTiles(inContents);
    Result<std::unique_ptr<NavMeshFileWriter>> writer = NavMeshFileWriter::Create(inPath, inContents.mParams);
    if (!writer) return writer.GetError();
    for (const NavMeshFileTile& tile : inContents.mTiles)
        if (Status added = writer.Value()->Add(tile.mTile, tile.mData); !added) return added;
    return writer.Value()->Finish();
}

Result<NavMeshFileContents> LoadNavMeshFile(const std::string& inPath)
{
    std::error_code error;
    if (!std::filesystem::is_regular_file(inPath, error))
        return MakeError(ErrorCode::IOError, inPath + ": not a readable file");
    std::ifstream in(inPath, std::ios::binary);
    if (!in) return MakeError(ErrorCode::IOError, inPath + ": cannot be read");
    const uintmax_t fileSize = std::filesystem::file_size(inPath, error);
    if (error) return MakeError(ErrorCode::IOError, inPath + ": cannot be read");
    auto parseError = [&](const std::string& inWhat)
    { return MakeError(ErrorCode::ParseError, inPath + ": " + inWhat); };
    SetHeader header;
    if (!in.read(reinterpret_cast<char*>(&header), sizeof(header)))
        return parseError("shorter than a navmesh set header");
    if (header.mMagic != cSetMagic) return parseError("not a navmesh set (magic)");
    if (header.mVersion != cSetVersion)
        return parseError("navmesh set version " + std::to_string(header.mVersion) + ", expected 1");
    if (const std::string problem = CheckNavMeshParams(header.mParams); !problem.empty())
        return parseError("navmesh parameters: " + problem);
    // Every count is held to what the file's bytes can hold before anything is allocated for it
    uintmax_t remaining = fileSize - sizeof(header);
    if (header.mNumTiles < 0 || header.mNumTiles > header.mParams.maxTiles ||
        uintmax_t(header.mNumTiles) > remaining / (sizeof(TileHeader) + sizeof(dtMeshHeader)))
        return parseError("tile count " + std::to_string(header.mNumTiles) +
                          " is negative, over max tiles or more than the file's bytes hold");
    NavMeshFileContents contents;
    contents.mParams = header.mParams;
    std::set<std::tuple<int, int, int>> places;
    for (int32_t i = 0; i < header.mNumTiles; ++i)
    {
        const std::string where = "tile " + std::to_string(i) + ": ";
        TileHeader tileHeader;
        if (!in.read(reinterpret_cast<char*>(&tileHeader), sizeof(tileHeader)))
            return parseError(where + "truncated header");
        remaining -= sizeof(tileHeader);
        if (tileHeader.mTileRef == 0 || tileHeader.mDataSize <= 0 ||
            uintmax_t(tileHeader.mDataSize) > remaining)
            return parseError(where + "bad reference, or a size of " + std::to_string(tileHeader.mDataSize) +
                              " bytes where " + std::to_string(remaining) + " remain");
        remaining -= uintmax_t(tileHeader.mDataSize);
        NavMeshFileTile tile;
        tile.mData.resize(size_t(tileHeader.mDataSize));
        if (!in.read(reinterpret_cast<char*>(tile.mData.data()), tileHeader.mDataSize))
            return parseError(where + "truncated data");
        if (const std::string problem = CheckTileData(tile.mData); !problem.empty())
            return parseError(where + problem);
        if (const std::string problem = CheckTileFitsParams(tile.mData, header.mParams); !problem.empty())
            return parseError(where + problem);
        const dtMeshHeader tileMeshHeader = ReadAt<dtMeshHeader>(tile.mData, 0, 0);
        if (!places.emplace(tileMeshHeader.x, tileMeshHeader.y, tileMeshHeader.layer).second)
            return parseError(where + "a second tile at (" + std::to_string(tileMeshHeader.x) + ", " +
                              std::to_string(tileMeshHeader.y) + ") layer " +
                              std::to_string(tileMeshHeader.layer));
        (void)ReadTileCoord(tile.mData, tile.mTile); // Checked above
        contents.mTiles.push_back(std::move(tile));
    }
    // A tile count lower than the tiles that follow would drop tiles without a word
    if (remaining != 0)
        return parseError(std::to_string(remaining) + " bytes follow the " +
                          std::to_string(header.mNumTiles) + " tiles its header counts");
    SortTiles(contents);
    return contents;
}

Result<DetourNavMeshPtr> CreateDetourNavMesh(const NavMeshFileContents& inContents)
{
    if (const std::string problem = CheckNavMeshParams(inContents.mParams); !problem.empty())
        return MakeError(ErrorCode::InvalidArgument, "navmesh: " + problem);
    DetourNavMeshPtr navMesh(dtAllocNavMesh());
    if (navMesh == nullptr || dtStatusFailed(navMesh->init(&inContents.mParams)))
        return MakeError(ErrorCode::InvalidArgument, "navmesh: the parameters are invalid");
    for (const NavMeshFileTile& tile : inContents.mTiles)
    {
        std::string problem = CheckTileData(tile.mData);
        if (problem.empty()) problem = CheckTileFitsParams(tile.mData, inContents.mParams);
        if (!problem.empty())
            return MakeError(ErrorCode::InvalidArgument, "navmesh: tile (" + std::to_string(tile.mTile.mX) +
                                                             ", " + std::to_string(tile.mTile.mZ) +
                                                             "): " + problem);
        auto* data = static_cast<unsigned char*>(dtAlloc(tile.mData.size(), DT_ALLOC_PERM));
        if (data == nullptr) return MakeError(ErrorCode::OutOfCapacity, "navmesh: out of memory");
        std::memcpy(data, tile.mData.data(), tile.mData.size());
        if (dtStatusFailed(navMesh->addTile(data, int(tile.mData.size()), DT_TILE_FREE_DATA, 0, nullptr)))
        {
            dtFree(data);
            return MakeError(ErrorCode::InvalidArgument, "navmesh: tile (" + std::to_string(tile.mTile.mX) +
                                                             ", " + std::to_string(tile.mTile.mZ) +
                                                             ") could not be added");
        }
    }
    return navMesh;
}

} // namespace cairn::navmesh
