#pragma once

// Mix64: splitmix64's finalizer, the integer hash the tools' generated worlds (the demo's world, the baker's
// generated level) make their random values from: a bijection where every input bit changes about half the
// output bits, the same on every platform (unlike the standard library's distributions). Any thread.

#include <cstdint>

namespace cairn::tools
{
using namespace cairn::physics;

inline uint64_t Mix64(uint64_t inValue)
{
    inValue ^= inValue >> 30;
    inValue *= 0xbf58476d1ce4e5b9ull;
    inValue ^= inValue >> 27;
    inValue *= 0x94d049bb133111ebull;
    return inValue ^ (inValue >> 31);
}

} // namespace cairn::tools
