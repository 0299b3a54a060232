#pragma once

// OffMeshLinksFile: the off-mesh links of a bake (jumps, drops, ladders: where agents cross what the navmesh
// cannot walk) from a JSON file beside the level, as a level editor's link markers would be exported:
//   { "links": [ { "start": [-2.5, 0, 0], "end": [2.5, 0, 0], "radius": 0.6, "bidirectional": true,
//                  "area": 0, "user_id": 7 } ] }
// "start" and "end" are world positions (metres); the rest is optional: radius (how near the navmesh an end
// must be to join it, default 0.5 m), bidirectional (default true; false: a drop, start to end only), area
// (the path costs' area id, default 0) and user_id (the game's id of the link, kept in the navmesh, default
// 0). An unknown key is an error, so a typo is not ignored. Any thread.

#include "cairn/navmesh/TileBuilder.h"

#include <string>
#include <vector>

namespace cairn::bake
{
using namespace cairn::physics;

/// The most links one file may hold: far more than a level places by hand, few enough that a wrong count
/// is an error rather than gigabytes.
inline constexpr size_t cMaxOffMeshLinks = size_t(1) << 20;

/// The links of inPath, in the file's order. Errors name the file and the link (its index) and key: not a
/// JSON object of that form, a position that is not three numbers within the world's range, a radius not in
/// (0, 1000] m, an
/// area over navmesh::cMaxAreaId, a user id that is not a whole number from 0 to 2^32 - 1, more than
/// cMaxOffMeshLinks links.
Result<std::vector<navmesh::OffMeshLink>> LoadOffMeshLinks(const std::string& inPath);

} // namespace cairn::bake
