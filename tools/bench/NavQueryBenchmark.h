#pragma once

// nav_queries_world_tile0 of cairn-bench-navmesh: the published navmesh's queries, one thread, no Publish
// beside them.

#include "common/SharedBenchData.h"

namespace cairn::tools
{

/// Builds and publishes the navmesh over world tile 0 of the shared static world, then times FindPath,
/// Raycast and FindNearestWall between seeded random points on it: µs per query (mean, p50, p99), medians
/// over inRepetitions, with the answers' counts as the checksum.
void RunNavQueries(const SharedBenchData& inData, int inRepetitions);

} // namespace cairn::tools
