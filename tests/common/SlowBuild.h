#pragma once

// Whether this build runs the tests' checks many times slower than an optimised one.

namespace cairn::test
{

/// A build whose checks run many times slower than an optimised one (sanitizers, no optimisation): the stress
/// runs keep shorter time caps there and require a lower floor of checks instead of the full target.
inline constexpr bool cSlowBuild =
#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__) || !defined(__OPTIMIZE__)
    true;
#else
    false;
#endif

} // namespace cairn::test
