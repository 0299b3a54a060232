#pragma once

// BodyID: a body's slot index plus a sequence number that changes every time the slot is reused, so that a
// stale id (its body destroyed, the slot given to another) is detected instead of touching the wrong body.
// Plain value type.

#include <compare>
#include <cstdint>
#include <functional>

namespace cairn::physics
{

class BodyID
{
public:
    static constexpr uint32_t cInvalidIndex = 0xffffffffu;

    constexpr BodyID() = default;
    constexpr BodyID(uint32_t inIndex, uint32_t inSequence) : mIndex(inIndex), mSequence(inSequence) {}

    constexpr uint32_t GetIndex() const { return mIndex; }       ///< Slot in the body manager
    constexpr uint32_t GetSequence() const { return mSequence; } ///< Generation of that slot
    constexpr bool IsInvalid() const { return mIndex == cInvalidIndex; }

    constexpr auto operator<=>(const BodyID&) const = default;

private:
    uint32_t mIndex = cInvalidIndex;
    uint32_t mSequence = 0;
};

} // namespace cairn::physics

template <> struct std::hash<cairn::physics::BodyID>
{
    size_t operator()(const cairn::physics::BodyID& inID) const noexcept
    {
        return std::hash<uint64_t>()((uint64_t(inID.GetSequence()) << 32) | inID.GetIndex());
    }
};
