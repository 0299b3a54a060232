#include "cairn/navmesh/NavMeshFile.h"

#include "cairn/navmesh/ReplaceFile.h"

#include <DetourAlloc.h>
#include <DetourCommon.h>
#include <DetourNavMesh.h>
#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

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
    section(3 * sizeof(float), h.detailVertCount);
    const size_t detailTris = section(4, h.detailTriCount);
    const size_t bvNodes = section(sizeof(dtBVNode), h.bvNodeCount);
    const size_t offMesh = section(sizeof(dtOffMeshConnection), h.offMeshConCount);
    (void)verts;
    if (offset > inData.size())
        return "its sections need " + std::to_string(offset) + " bytes, it has " +
               std::to_string(inData.size());
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
        for (int t = 0; t < detail.triCount; ++t)
            for (int k = 0; k < 3; ++k)
                if (ReadAt<unsigned char>(inData, detailTris,
                                          (size_t(detail.triBase) + size_t(t)) * 4 + size_t(k)) >=
                    poly.vertCount + detail.vertCount)
                    return "a detail triangle of polygon " + std::to_string(i) + " names a missing vertex";
    }
    for (int i = 0; i < h.bvNodeCount; ++i)
    {
        const int index = ReadAt<dtBVNode>(inData, bvNodes, size_t(i)).i;
        if (index >= h.polyCount || (index < 0 && (index == INT32_MIN || -index > h.bvNodeCount - i)))
            return "bounding-volume node " + std::to_string(i) + " points outside the tree";
    }
    for (int i = 0; i < h.offMeshConCount; ++i)
        if (ReadAt<dtOffMeshConnection>(inData, offMesh, size_t(i)).poly >= h.polyCount)
            return "off-mesh connection " + std::to_string(i) + " names a missing polygon";
    return "";
}

Result<dtNavMeshParams> MakeNavMeshParams(const TileGrid& inGrid, int inMaxTiles)
{
    if (inMaxTiles < 1 || inMaxTiles > (1 << 20))
        return MakeError(ErrorCode::InvalidArgument, "navmesh: max tiles must be 1 to 2^20");
    // A 32-bit polygon reference holds salt, tile and polygon bits: tiles take what they need, polygons get
    // the rest up to 22 (10 bits of salt, as Detour's samples leave)
    int tileBits = 0;
    while ((1 << tileBits) < inMaxTiles)
        ++tileBits;
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

Status NavMeshFileWriter::Finish()
{
    const SetHeader header{cSetMagic, cSetVersion, mNumTiles, mParams};
    mFile.Stream().seekp(0);
    mFile.Stream().write(reinterpret_cast<const char*>(&header), sizeof(header));
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
    std::ifstream in(inPath, std::ios::binary);
    if (!in) return MakeError(ErrorCode::IOError, inPath + ": cannot be read");
    SetHeader header;
    if (!in.read(reinterpret_cast<char*>(&header), sizeof(header)))
        return MakeError(ErrorCode::ParseError, inPath + ": shorter than a navmesh set header");
    if (header.mMagic != cSetMagic)
        return MakeError(ErrorCode::ParseError, inPath + ": not a navmesh set (magic)");
    if (header.mVersion != cSetVersion)
        return MakeError(ErrorCode::ParseError, inPath + ": navmesh set version " +
                                                    std::to_string(header.mVersion) + ", expected 1");
    if (header.mNumTiles < 0 || header.mNumTiles > header.mParams.maxTiles)
        return MakeError(ErrorCode::ParseError, inPath + ": tile count out of range");
    NavMeshFileContents contents;
    contents.mParams = header.mParams;
    for (int32_t i = 0; i < header.mNumTiles; ++i)
    {
        TileHeader tileHeader;
        if (!in.read(reinterpret_cast<char*>(&tileHeader), sizeof(tileHeader)))
            return MakeError(ErrorCode::ParseError,
                             inPath + ": tile " + std::to_string(i) + ": truncated header");
        if (tileHeader.mTileRef == 0 || tileHeader.mDataSize <= 0 || tileHeader.mDataSize > (1 << 28))
            return MakeError(ErrorCode::ParseError,
                             inPath + ": tile " + std::to_string(i) + ": bad reference or size");
        NavMeshFileTile tile;
        tile.mData.resize(size_t(tileHeader.mDataSize));
        if (!in.read(reinterpret_cast<char*>(tile.mData.data()), tileHeader.mDataSize))
            return MakeError(ErrorCode::ParseError,
                             inPath + ": tile " + std::to_string(i) + ": truncated data");
        if (const std::string problem = CheckTileData(tile.mData); !problem.empty())
            return MakeError(ErrorCode::ParseError, inPath + ": tile " + std::to_string(i) + ": " + problem);
        (void)ReadTileCoord(tile.mData, tile.mTile); // Checked above
        contents.mTiles.push_back(std::move(tile));
    }
    SortTiles(contents);
    return contents;
}

Result<DetourNavMeshPtr> CreateDetourNavMesh(const NavMeshFileContents& inContents)
{
    DetourNavMeshPtr navMesh(dtAllocNavMesh());
    if (navMesh == nullptr || dtStatusFailed(navMesh->init(&inContents.mParams)))
        return MakeError(ErrorCode::InvalidArgument, "navmesh: the parameters are invalid");
    for (const NavMeshFileTile& tile : inContents.mTiles)
    {
        if (const std::string problem = CheckTileData(tile.mData); !problem.empty())
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
