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
