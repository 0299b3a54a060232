#pragma once

// Counts heap allocations made through the global operator new, so tests can prove a hot path allocates
// nothing. Linking cairn_test_common replaces the global operator new/delete of the test program with
// counting versions.

#include <atomic>
#include <cstdint>

namespace cairn::test
{

/// Allocations made by any thread since the program started.
uint64_t GetAllocationCount();

/// Allocations made during the lifetime of an instance (by any thread).
class AllocationScope
{
public:
    AllocationScope() : mStart(GetAllocationCount()) {}
    uint64_t GetCount() const { return GetAllocationCount() - mStart; }

private:
    uint64_t mStart;
};

} // namespace cairn::test
