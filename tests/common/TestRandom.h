#pragma once

// Deterministic random values for tests that build random worlds: uniform floats and indices, coin flips, and
// coordinates snapped to a 0.5 m grid half of the time so that touching boxes and rays along faces are
// common.

#include <cmath>
#include <cstdint>
#include <random>

namespace cairn::test
{
using namespace cairn::physics;

class TestRandom
{
public:
    explicit TestRandom(uint32_t inSeed) : mRandom(inSeed) {}

    float Uniform(float inMin, float inMax)
    {
        return std::uniform_real_distribution<float>(inMin, inMax)(mRandom);
    }
    uint32_t Index(uint32_t inCount)
    {
        return std::uniform_int_distribution<uint32_t>(0, inCount - 1)(mRandom);
    }
    bool Chance(float inProbability) { return Uniform(0.0f, 1.0f) < inProbability; }

    /// A coordinate in [inMin, inMax], on the 0.5 m grid half of the time.
    float Coordinate(float inMin, float inMax)
    {
        const float value = Uniform(inMin, inMax);
        return Chance(0.5f) ? std::round(value * 2.0f) * 0.5f : value;
    }

    std::mt19937 mRandom; ///< Deterministic per seed
};

} // namespace cairn::test
