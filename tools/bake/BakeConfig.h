#pragma once

// BakeConfig: the agent profile and tile size of a bake from a JSON file (nlohmann-json), so that a level's
// settings live next to it:
//   { "agent_height": 2.0, "agent_radius": 0.6, "agent_max_climb": 0.9, "agent_max_slope": 45,
//     "cell_size": 0.2, "cell_height": 0.2, "tile_size": 12.8, "region_partition": "watershed",
//     "region_min_size": 8, "region_merge_size": 20, "edge_max_length": 12, "edge_max_error": 1.3,
//     "max_verts_per_poly": 6, "detail_sample_distance": 6, "detail_sample_max_error": 1 }
// Every key is optional (the profile's defaults stay); an unknown key is an error, so a typo is not ignored.

#include "cairn/navmesh/AgentProfile.h"
#include "cairn/navmesh/LevelMesh.h"

#include <string>

namespace cairn::bake
{
using namespace cairn::physics;

/// Reads inPath into ioProfile (keys it does not name keep their values) and validates the result. Errors
/// name the file and the key.
Status LoadBakeConfig(const std::string& inPath, navmesh::AgentProfile& ioProfile);

/// Reads an area mapping (material names to navmesh area ids, see navmesh::AreaMapping) from a JSON file:
///   { "default": 0, "materials": { "road": 1, "grass": 2, "shallow_water": 3 } }
/// Both keys are optional; ids are whole numbers from 0 to navmesh::cMaxAreaId. Errors name the file and the
/// key or material.
Result<navmesh::AreaMapping> LoadAreaMapping(const std::string& inPath);

} // namespace cairn::bake
