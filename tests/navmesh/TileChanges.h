#pragma once

// The changes one NavMeshWorld::Publish takes, made from a tile or a removal in one expression.

#include "cairn/navmesh/NavMeshWorld.h"

#include <vector>

namespace cairn::navmesh::test
{
using namespace cairn::physics;

inline std::vector<BuiltTile> Changes(BuiltTile&& inChange)
{
    std::vector<BuiltTile> changes;
    changes.push_back(std::move(inChange));
    return changes;
}

} // namespace cairn::navmesh::test
