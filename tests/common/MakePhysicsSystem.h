#pragma once

// The tests' way to a world: PhysicsSystem::Create without the Result at every site, for tests whose setups
// are meant to be valid (SetupValidationTest calls Create itself to check its errors).

#include "cairn/physics/PhysicsSystem.h"

#include <memory>
#include <stdexcept>
#include <string>

namespace cairn::test
{
using namespace cairn::physics;

/// A world from inSettings and inLayers. When Create refuses them, the test fails with Create's error: as an
/// exception, which gtest reports with its message and which ends the test, since a helper that returns a
/// value can not ASSERT and no test can go on without its world.
inline std::unique_ptr<PhysicsSystem>
MakePhysicsSystem(const PhysicsSettings& inSettings = {},
                  const LayerSetup& inLayers = LayerSetup::CreateDefault())
{
    Result<std::unique_ptr<PhysicsSystem>> system = PhysicsSystem::Create(inSettings, inLayers);
    if (!system)
        throw std::invalid_argument(std::string("PhysicsSystem::Create: ") +
                                    ToString(system.GetError().mCode) + ": " + system.GetError().mMessage);
    return std::move(system).Value();
}

} // namespace cairn::test
