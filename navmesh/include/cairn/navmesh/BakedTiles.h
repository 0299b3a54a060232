#pragma once

// BakedTiles: a baked navmesh (cairn-bake's file, or Recast's demo's) put to use at run time, in a
// NavMeshWorld, where the path queries, the surface queries and the crowd work on it as on tiles built from
// the live physics world. A streaming game publishes a region's baked tiles as the region loads (and their
// Removals as it goes), at the same sync point as the rest of its navmesh changes. A TileScheduler on the
// same world builds its own needed tiles from the physics world, over baked ones: give it the regions that
// change at run time, and keep baked regions out of its invokers' and areas' reach.
//
// Threads: plain functions over plain data, any thread; NavMeshWorld::Publish is the world's.

#include "cairn/navmesh/NavMeshFile.h"
#include "cairn/navmesh/NavMeshWorld.h"
#include "cairn/navmesh/TileBuilder.h"
#include "cairn/physics/math/AABB.h"

#include <optional>
#include <vector>

namespace cairn::navmesh
{
using namespace cairn::physics;

/// The tiles of inContents as changes for inWorld's Publish (copies in Detour's allocation, in the file's
/// order), only those whose tile overlaps inRegion (x and z) when it is set. Errors: the file was baked on
/// another grid than inWorld's (its origin or tile size: every tile would be refused), a tile was baked for
/// another agent (its height, radius or climb not the world's profile's: agents would fit where they do
/// not), a region that is not a box of finite numbers.
Result<std::vector<BuiltTile>> MakeBakedTileChanges(const NavMeshFileContents& inContents,
                                                    const NavMeshWorld& inWorld,
                                                    const std::optional<AABB>& inRegion = std::nullopt);

} // namespace cairn::navmesh
