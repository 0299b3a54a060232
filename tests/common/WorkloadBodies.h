#pragma once

// The shared workload's boxes as bodies, as step_pile2k and the navmesh benchmarks make them: for the tests
// and the benchmarks that step that world.

#include "cairn/physics/body/BodyInterface.h"
#include "common/SharedBenchData.h"

#include <vector>

namespace cairn
{

/// A box of the workload: density 1000, friction 0.5, no restitution, turned by its yaw about +Y; static
/// boxes in the static layer, the others in the moving one.
physics::BodyCreationSettings WorkloadBoxSettings(const BenchBox& inBox, physics::MotionType inMotion);

/// Adds inBoxes in one batch, as a streaming loader would: static ones asleep, the others active unless
/// inActivateDynamic is false. Returns their ids in order (empty, with nothing added, when the world refuses
/// them).
std::vector<physics::BodyID> AddWorkloadBoxes(physics::BodyInterface& ioBodies,
                                              const std::vector<BenchBox>& inBoxes,
                                              physics::MotionType inMotion, bool inActivateDynamic = true);

} // namespace cairn
