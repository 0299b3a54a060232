#pragma once

// OffMeshLinkJoins: whether Detour joined an off-mesh link to the navmesh. Detour joins a link's start to the
// nearest polygon of its own tile, and then its end to the nearest polygon of the tile the end lies in, each
// within the link's radius across and the agent's climb up or down, as the tiles are added; an end with no
// polygon there stays unjoined without a word, and the link is one no agent can take. Detour's tile builder
// also leaves out a link whose start is above or below its tile's navmesh. Read from the links Detour made
// (for NavMeshWorld::GetOffMeshLinkState and the baker's link check); the caller holds the navmesh.

#include "cairn/physics/math/Math.h"

#include <DetourNavMesh.h>

namespace cairn::navmesh
{
using namespace cairn::physics;

struct OffMeshLinkJoins
{
    bool mStart = false;
    bool mEnd = false; ///< Detour tries the end only once the start is joined
};

/// The joins of inTile's off-mesh connection inConnection (an index into its offMeshCons).
OffMeshLinkJoins GetOffMeshLinkJoins(const dtMeshTile& inTile, int inConnection);

/// The index in inTile's offMeshCons of the connection from inStart to inEnd (each within a millimetre), -1
/// for none: the tile was built without it.
int FindOffMeshConnection(const dtMeshTile& inTile, const Vec3& inStart, const Vec3& inEnd);

} // namespace cairn::navmesh
