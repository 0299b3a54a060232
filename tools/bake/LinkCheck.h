#pragma once

// LinkCheck: the off-mesh links of a baked navmesh that agents can never take. Detour joins a link's start to
// the nearest polygon of its own tile and its end to the nearest of the tile it lies in, each within the
// link's radius across and the agent's climb up or down, when the tiles are loaded; an end with no polygon
// there is left unjoined without a word, and the link is dead: a ladder whose foot is a metre off the ground
// a level designer moved. And Detour's tile builder keeps a link only where its start is within the heights
// of its tile's navmesh: one whose start is in the air is dropped from the tile, again without a word. The
// check loads the tiles into a Detour navmesh as the runtime would and reads the links Detour made
// (navmesh/OffMeshLinkJoins.h, as NavMeshWorld::GetOffMeshLinkState does at run time). Any thread.

#include "cairn/navmesh/NavMeshFile.h"
#include "cairn/navmesh/TileBuilder.h"

#include <span>
#include <string>
#include <vector>

namespace cairn::bake
{
using namespace cairn::physics;

/// An off-mesh link with an end Detour did not join, or one its tile builder left out.
struct UnjoinedLink
{
    bool mBuilt = true; ///< False: declared for the bake, but not in its tile's data (the rest as declared)
    navmesh::TileCoord mTile; ///< The tile that holds it (its start's)
    Vec3 mStart = Vec3::Zero();
    Vec3 mEnd = Vec3::Zero();
    uint32_t mUserID = 0;
    bool mStartJoined = false;
    bool mEndJoined = false; ///< Detour tries the end only once the start is joined
};

/// The links of inNavMesh's tiles whose start or end joins no polygon, found in a Detour navmesh of the tiles
/// with links and those next to them only (where a link may end). An end in a tile inNavMesh does not hold
/// counts as unjoined: give it every tile a link may end in. In tile order, then the order of the links in
/// their tile; then inDeclared's links (those the bake built in, each in the tile its start lies in) that are
/// in no tile's data, in their order, where inNavMesh holds their tile. Errors: data Detour refuses
/// (CreateDetourNavMesh's).
Result<std::vector<UnjoinedLink>> FindUnjoinedLinks(const navmesh::NavMeshFileContents& inNavMesh,
                                                    std::span<const navmesh::OffMeshLink> inDeclared = {});

/// Whether inTile or one of the eight around it is in inTilesWithLinks (a set of tiles, or a map by tile):
/// the tiles a link of those tiles may end in.
template <class TileSet> bool IsNearLinks(const navmesh::TileCoord& inTile, const TileSet& inTilesWithLinks)
{
    for (int dx = -1; dx <= 1; ++dx)
        for (int dz = -1; dz <= 1; ++dz)
            if (inTilesWithLinks.contains(navmesh::TileCoord{inTile.mX + dx, inTile.mZ + dz})) return true;
    return false;
}

/// One line for a link: where it is, which end does not join, and why that matters.
std::string DescribeUnjoinedLink(const UnjoinedLink& inLink);

} // namespace cairn::bake
