#include "cairn/navmesh/OffMeshLinkJoins.h"

namespace cairn::navmesh
{

OffMeshLinkJoins GetOffMeshLinkJoins(const dtMeshTile& inTile, int inConnection)
{
    // The links of a connection's polygon: Detour's edge 0 to the polygon its start joined, edge 1 to its
    // end's
    const dtPoly& polygon = inTile.polys[inTile.offMeshCons[inConnection].poly];
    OffMeshLinkJoins joins;
    for (unsigned int k = polygon.firstLink; k != DT_NULL_LINK; k = inTile.links[k].next)
    {
        joins.mStart |= inTile.links[k].edge == 0;
        joins.mEnd |= inTile.links[k].edge == 1;
    }
    return joins;
}

int FindOffMeshConnection(const dtMeshTile& inTile, const Vec3& inStart, const Vec3& inEnd)
{
    for (int c = 0; c < inTile.header->offMeshConCount; ++c)
    {
        const float* pos = inTile.offMeshCons[c].pos;
        if ((Vec3(pos[0], pos[1], pos[2]) - inStart).norm() < 1.0e-3f &&
            (Vec3(pos[3], pos[4], pos[5]) - inEnd).norm() < 1.0e-3f)
            return c;
    }
    return -1;
}

} // namespace cairn::navmesh
