#pragma once

#include <cstdint>

namespace cairn::physics
{

enum class MotionType : uint8_t
{
    Static,    ///< Never moves; never joins an island
    Kinematic, ///< Moved by its velocity only; infinite mass; never joins an island
    Dynamic,   ///< Moved by forces and contacts
};

/// Whether AddBody makes a dynamic or kinematic body active (simulated) right away.
enum class Activation : uint8_t
{
    Activate,
    DontActivate,
};

} // namespace cairn::physics
