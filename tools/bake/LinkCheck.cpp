#include "LinkCheck.h"

#include "cairn/navmesh/OffMeshLinkJoins.h"

#include <DetourNavMesh.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <set>

namespace cairn::bake
{

Result<std::vector<UnjoinedLink>> FindUnjoinedLinks(const navmesh::NavMeshFileContents& inNavMesh,
                                                    std::span<const navmesh::OffMeshLink> inDeclared)
{
    // Only the tiles with links and those next to them, where their ends can lie: a whole world's navmesh
    // need not be made twice
    std::set<navmesh::TileCoord> withLinks;
    for (const navmesh::NavMeshFileTile& tile : inNavMesh.mTiles)
    {
        dtMeshHeader header;
        if (tile.mData.size() < sizeof(header)) continue; // CreateDetourNavMesh refuses it below
        std::memcpy(&header, tile.mData.data(), sizeof(header));
        if (header.offMeshConCount > 0) withLinks.insert(tile.mTile);
    }
    // The declared links' tiles too, to look for them there
    const float tileWidth = inNavMesh.mParams.tileWidth, tileHeight = inNavMesh.mParams.tileHeight;
    auto tileOf = [&](const Vec3& inPoint)
    {
        return navmesh::TileCoord{int(std::floor((inPoint.x() - inNavMesh.mParams.orig[0]) / tileWidth)),
                                  int(std::floor((inPoint.z() - inNavMesh.mParams.orig[2]) / tileHeight))};
    };
    for (const navmesh::OffMeshLink& link : inDeclared)
        withLinks.insert(tileOf(link.mStart));
    if (withLinks.empty()) return std::vector<UnjoinedLink>();
    const auto kept = [&](const navmesh::NavMeshFileTile& inTile)
    { return IsNearLinks(inTile.mTile, withLinks) || inTile.mData.size() < sizeof(dtMeshHeader); };
    // Copied only when some tiles are left out (a bake hands in just the tiles near its links)
    navmesh::NavMeshFileContents copied;
    const bool keepsAll = std::all_of(inNavMesh.mTiles.begin(), inNavMesh.mTiles.end(), kept);
    if (!keepsAll)
    {
        copied.mParams = inNavMesh.mParams;
        std::copy_if(inNavMesh.mTiles.begin(), inNavMesh.mTiles.end(), std::back_inserter(copied.mTiles),
                     kept);
    }
    const navmesh::NavMeshFileContents& near = keepsAll ? inNavMesh : copied;
    Result<navmesh::DetourNavMeshPtr> created = navmesh::CreateDetourNavMesh(near);
    if (!created) return created.GetError();
    const dtNavMesh& navMesh = *created.Value();
    std::vector<UnjoinedLink> unjoined;
    for (const navmesh::NavMeshFileTile& fileTile : near.mTiles)
    {
        const dtMeshTile* tile = navMesh.getTileAt(fileTile.mTile.mX, fileTile.mTile.mZ, 0);
        if (tile == nullptr || tile->header == nullptr) continue;
        for (int c = 0; c < tile->header->offMeshConCount; ++c)
        {
            const dtOffMeshConnection& connection = tile->offMeshCons[c];
            const navmesh::OffMeshLinkJoins joins = navmesh::GetOffMeshLinkJoins(*tile, c);
            if (joins.mStart && joins.mEnd) continue;
            unjoined.push_back({.mTile = fileTile.mTile,
                                .mStart = Vec3(connection.pos[0], connection.pos[1], connection.pos[2]),
                                .mEnd = Vec3(connection.pos[3], connection.pos[4], connection.pos[5]),
                                .mUserID = connection.userId,
                                .mStartJoined = joins.mStart,
                                .mEndJoined = joins.mEnd});
        }
    }
    // Declared links their tile's data does not hold: Detour's builder left them out
    for (const navmesh::OffMeshLink& link : inDeclared)
    {
        const navmesh::TileCoord coord = tileOf(link.mStart);
        const dtMeshTile* tile = navMesh.getTileAt(coord.mX, coord.mZ, 0);
        if (tile == nullptr || tile->header == nullptr) continue; // Not a tile given
        if (navmesh::FindOffMeshConnection(*tile, link.mStart, link.mEnd) >= 0) continue;
        unjoined.push_back({.mBuilt = false,
                            .mTile = coord,
                            .mStart = link.mStart,
                            .mEnd = link.mEnd,
                            .mUserID = link.mUserID});
    }
    return unjoined;
}

std::string DescribeUnjoinedLink(const UnjoinedLink& inLink)
{
    // Detour joins the end only after the start: an unjoined start leaves the end unjoined too
    const char* which = !inLink.mStartJoined ? "its start" : "its end";
    const std::string what =
        inLink.mBuilt
            ? std::string(which) + " joins no navmesh within its radius (and the agent's climb up or down)"
            : "is not in the navmesh: Detour keeps a link only where its start is within the heights of its "
              "tile's navmesh";
    char text[640];
    std::snprintf(
        text, sizeof(text),
        "off-mesh link (user id %u) from (%.2f, %.2f, %.2f) to (%.2f, %.2f, %.2f) in tile (%d, %d): %s: "
        "no agent can take it",
        inLink.mUserID, double(inLink.mStart.x()), double(inLink.mStart.y()), double(inLink.mStart.z()),
        double(inLink.mEnd.x()), double(inLink.mEnd.y()), double(inLink.mEnd.z()), inLink.mTile.mX,
        inLink.mTile.mZ, what.c_str());
    return text;
}

} // namespace cairn::bake
