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
using namespace cairn::physics;

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
        dtMeshHeader tileMeshHeader;
        std::memcpy(&tileMeshHeader, tile.mData.data(), sizeof(tileMeshHeader));
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
