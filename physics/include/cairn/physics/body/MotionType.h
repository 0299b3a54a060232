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

/// Whether inType is one of the three: a value cast from a number (a file, a script) may be none of them.
constexpr bool IsValidMotionType(MotionType inType)
{
    return inType == MotionType::Static || inType == MotionType::Kinematic || inType == MotionType::Dynamic;
}

/// How a dynamic body's motion is checked against what it could pass through in one step.
enum class MotionQuality : uint8_t
{
    /// Speculative contacts only: a body meets what it heads for, found from where it starts the step (enough
    /// for nearly every body, and the cheapest)
    Discrete,
    /// Also swept from where it started the step to where the solver put it, and stopped at the first thing
    /// it would touch (a time-of-impact cast, translation only, at its final rotation): fast small bodies
    /// (projectiles) never pass through a thin wall. The contact itself is then the next step's
    LinearCast,
};

/// Whether AddBody makes a dynamic or kinematic body active (simulated) right away.
enum class Activation : uint8_t
{
    Activate,
    DontActivate,
};

} // namespace cairn::physics
