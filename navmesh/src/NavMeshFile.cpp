#include "cairn/navmesh/NavMeshFile.h"

#include "cairn/navmesh/ReplaceFile.h"

#include <DetourAlloc.h>
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

void SortTiles(NavMeshFileContents& ioContents)
{
    std::sort(ioContents.mTiles.begin(), ioContents.mTiles.end(),
              [](const NavMeshFileTile& inL, const NavMeshFileTile& inR) { return inL.mTile < inR.mTile; });
}
} // namespace

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

Status SaveNavMeshFile(const std::string& inPath, NavMeshFileContents inContents)
{
    SortTiles(inContents);
    // The references a fresh navmesh gives the tiles added in this order: tile slot i, salt 1
    DetourNavMeshPtr layout(dtAllocNavMesh());
    if (layout == nullptr || dtStatusFailed(layout->init(&inContents.mParams)))
        return MakeError(ErrorCode::InvalidArgument, inPath + ": the navmesh parameters are invalid");
    if (int64_t(inContents.mTiles.size()) > inContents.mParams.maxTiles)
        return MakeError(ErrorCode::OutOfCapacity, inPath + ": " + std::to_string(inContents.mTiles.size()) +
                                                       " tiles, more than the parameters allow (" +
                                                       std::to_string(inContents.mParams.maxTiles) + ")");

    return ReplaceFile(
        inPath,
        [&](std::ostream& ioOut)
        {
            SetHeader header{cSetMagic, cSetVersion, int32_t(inContents.mTiles.size()), inContents.mParams};
            ioOut.write(reinterpret_cast<const char*>(&header), sizeof(header));
            for (size_t i = 0; i < inContents.mTiles.size(); ++i)
            {
                const NavMeshFileTile& tile = inContents.mTiles[i];
                const TileHeader tileHeader{layout->encodePolyId(1, unsigned(i), 0),
                                            int32_t(tile.mData.size())};
                ioOut.write(reinterpret_cast<const char*>(&tileHeader), sizeof(tileHeader));
                ioOut.write(reinterpret_cast<const char*>(tile.mData.data()),
                            std::streamsize(tile.mData.size()));
            }
            return Status::Ok();
        });
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
        if (!ReadTileCoord(tile.mData, tile.mTile))
            return MakeError(ErrorCode::ParseError,
                             inPath + ": tile " + std::to_string(i) + ": not Detour tile data");
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
