#pragma once

// The physics world of a benchmark: PhysicsSystem::Create, or the program ends. A benchmark has nothing to
// measure without its world, and its settings come from the command line (--candidate-margin) or are fixed,
// so a refused setup is reported and ends the run rather than being passed up through every scene function.

#include "cairn/physics/PhysicsSystem.h"

#include <cstdio>
#include <cstdlib>
#include <memory>

namespace cairn::tools
{
using namespace cairn::physics;

/// A world from inSettings and inLayers; when Create refuses them, "inProgram: PhysicsSystem::Create: <the
/// error>" on stderr and exit status 1.
inline std::unique_ptr<PhysicsSystem>
CreatePhysicsSystemOrExit(const char* inProgram, const PhysicsSettings& inSettings,
                          const LayerSetup& inLayers = LayerSetup::CreateDefault())
{
    Result<std::unique_ptr<PhysicsSystem>> system = PhysicsSystem::Create(inSettings, inLayers);
    if (!system)
    {
        std::fprintf(stderr, "%s: PhysicsSystem::Create: %s\n", inProgram,
                     system.GetError().mMessage.c_str());
        std::exit(1);
    }
    return std::move(system).Value();
}

} // namespace cairn::tools
