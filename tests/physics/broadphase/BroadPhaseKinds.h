#pragma once

// The broad phases that the typed hand-made cases run on (BroadPhaseCasesTest, BroadPhaseChangeLayerTest),
// each made for 1,000 bodies and the default layers, and the bodies those cases place.

#include "broadphase/BroadPhaseBruteForce.h"
#include "broadphase/BroadPhaseGlobalMutex.h"
#include "broadphase/BroadPhaseQuadTree.h"

#include <gtest/gtest.h>
#include <memory>

namespace cairn::test
{

/// The quad tree behind BroadPhaseGlobalMutex (BroadPhaseType::QuadTreeGlobalMutex), as its own type for the
/// typed tests.
struct QuadTreeGlobalMutex
{
};
/// The oracle behind BroadPhaseGlobalMutex: the wrapper forwards to whatever it wraps.
struct BruteForceGlobalMutex
{
};

/// Creates a broad phase of kind T.
template <class T> std::unique_ptr<physics::BroadPhase> MakeBroadPhase();
template <> inline std::unique_ptr<physics::BroadPhase> MakeBroadPhase<physics::BroadPhaseBruteForce>()
{
    return std::make_unique<physics::BroadPhaseBruteForce>();
}
template <> inline std::unique_ptr<physics::BroadPhase> MakeBroadPhase<physics::BroadPhaseQuadTree>()
{
    return std::make_unique<physics::BroadPhaseQuadTree>(1000, physics::LayerSetup::CreateDefault());
}
template <> inline std::unique_ptr<physics::BroadPhase> MakeBroadPhase<QuadTreeGlobalMutex>()
{
    return std::make_unique<physics::BroadPhaseGlobalMutex>(
        std::make_unique<physics::BroadPhaseQuadTree>(1000, physics::LayerSetup::CreateDefault()));
}
template <> inline std::unique_ptr<physics::BroadPhase> MakeBroadPhase<BruteForceGlobalMutex>()
{
    return std::make_unique<physics::BroadPhaseGlobalMutex>(
        std::make_unique<physics::BroadPhaseBruteForce>());
}

using BroadPhaseKinds = ::testing::Types<physics::BroadPhaseBruteForce, physics::BroadPhaseQuadTree,
                                         QuadTreeGlobalMutex, BruteForceGlobalMutex>;

inline const physics::AABB cUnitBox(physics::Vec3(0, 0, 0), physics::Vec3(1, 1, 1));
inline const physics::BodyID cA(1, 1);
inline const physics::BodyID cB(2, 1);
inline const physics::BodyID cC(3, 1);
inline const physics::BodyID cD(4, 1);

} // namespace cairn::test
