#pragma once

// Object layers and broad-phase layers. An object layer says what a body is (static world, moving, debris,
// trigger...), a table says which object layers collide with which, and each object layer maps to one
// broad-phase layer (one broad-phase tree per broad-phase layer, e.g. static vs moving).
// LayerSetup is configured once before the world is created and read-only afterwards: any thread may read it.
// Misuse (a count or a layer id out of range) never writes out of bounds: the count is clamped or the call is
// ignored, and GetStatus reports the first such error (PhysicsSystem::Create refuses a setup whose status is
// not Ok).

#include "cairn/physics/math/Result.h"

#include <array>
#include <cstdint>
#include <string>

namespace cairn::physics
{

using ObjectLayer = uint8_t;
using BroadPhaseLayer = uint8_t;
/// Bit i set = object layer i included.
using ObjectLayerMask = uint64_t;

inline constexpr uint32_t cMaxObjectLayers = 64;
inline constexpr uint32_t cMaxBroadPhaseLayers = 8;
inline constexpr ObjectLayerMask cAllObjectLayers = ~ObjectLayerMask(0);

/// The layers of the default setup (LayerSetup::CreateDefault).
namespace Layers
{
inline constexpr ObjectLayer cStatic = 0; ///< World geometry: never moves; collides with moving and debris
inline constexpr ObjectLayer cMoving =
    1; ///< Dynamic and kinematic bodies: collide with everything but triggers
inline constexpr ObjectLayer cDebris = 2;  ///< Small dynamic bodies: collide with static only
inline constexpr ObjectLayer cTrigger = 3; ///< Sensors: found by queries, never collide
} // namespace Layers

namespace BroadPhaseLayers
{
inline constexpr BroadPhaseLayer cStatic = 0;
inline constexpr BroadPhaseLayer cMoving = 1;
} // namespace BroadPhaseLayers

class LayerSetup
{
public:
    /// inNumObjectLayers <= cMaxObjectLayers, inNumBroadPhaseLayers <= cMaxBroadPhaseLayers; all object
    /// layers start in broad-phase layer 0 and collide with nothing.
    LayerSetup(uint32_t inNumObjectLayers, uint32_t inNumBroadPhaseLayers);

    /// Static, Moving, Debris and Trigger object layers over Static and Moving broad-phase layers.
    static LayerSetup CreateDefault();

    /// Ok, or the first misuse since construction (see the top of this file).
    Status GetStatus() const;

    uint32_t GetNumObjectLayers() const { return mNumObjectLayers; }
    uint32_t GetNumBroadPhaseLayers() const { return mNumBroadPhaseLayers; }

    void SetBroadPhaseLayer(ObjectLayer inLayer, BroadPhaseLayer inBroadPhaseLayer);
    /// Symmetric: A collides with B iff B collides with A.
    void SetCollides(ObjectLayer inA, ObjectLayer inB, bool inCollides);

    // A layer past the setup (an ObjectLayer goes to 255, the tables to 63) is in broad-phase layer 0 and
    // collides with nothing: never a read past the tables, nor a shift past 63 bits
    bool IsValid(ObjectLayer inLayer) const { return inLayer < mNumObjectLayers; }
    BroadPhaseLayer GetBroadPhaseLayer(ObjectLayer inLayer) const
    {
        return IsValid(inLayer) ? mBroadPhaseLayer[inLayer] : BroadPhaseLayer(0);
    }
    bool ShouldCollide(ObjectLayer inA, ObjectLayer inB) const
    {
        return IsValid(inA) && IsValid(inB) && ((mCollidesWith[inA] >> inB) & 1u) != 0;
    }
    /// The object layers that inLayer collides with.
    ObjectLayerMask GetCollisionMask(ObjectLayer inLayer) const
    {
        return IsValid(inLayer) ? mCollidesWith[inLayer] : ObjectLayerMask(0);
    }
    /// The object layers that live in a broad-phase layer.
    ObjectLayerMask GetObjectLayersIn(BroadPhaseLayer inLayer) const;

private:
    uint32_t mNumObjectLayers;
    uint32_t mNumBroadPhaseLayers;
    std::array<BroadPhaseLayer, cMaxObjectLayers> mBroadPhaseLayer{};
    std::array<ObjectLayerMask, cMaxObjectLayers> mCollidesWith{};
    std::string mError; ///< The first misuse, empty when none

    void RecordError(std::string inMessage);
};

} // namespace cairn::physics
