#pragma once

// The demo's world as a JSON file (data/demo/world.json is the default), so that a world can be changed and
// kept without a rebuild:
//   { "seed": 1, "props_per_tile": 700, "dynamic_per_tile": 110, "buildings_per_tile": 2,
//   "collision_radius": 3.0,
//     "player_speed": 8.0, "throw_balls": true, "agents": 8, "game_objects": 256, "game_object_jobs": 8,
//     "collision_steps": 1, "candidate_margin": 0.25 }
// Every key is optional (the settings' values stay); an unknown key is an error, so a typo is not ignored.
// The run's own options (frames, threads, mode, real time) are flags, not world.

#include "DemoRunner.h"
#include "cairn/physics/math/Result.h"

#include <string>

namespace cairn::demo
{
using namespace cairn::physics;

/// Reads inPath into ioSettings and checks the world fits the demo's physics world (cDemoMaxBodies with the
/// tiles streaming in). Errors name the file and the key.
Status LoadDemoWorld(const std::string& inPath, DemoSettings& ioSettings);

/// The bodies a world of these settings may hold at once: its tiles around the player and around the point
/// ahead that streaming loads, each with its terrain, props and dynamic bodies, and the game objects.
uint64_t EstimateMaxBodies(const DemoSettings& inSettings);

} // namespace cairn::demo
