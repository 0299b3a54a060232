#include "common/AllocationCounter.h"

#include <cstddef>
#include <cstdlib>
#include <new>

namespace
{
// Relaxed: a statistic read after the counted work has been joined or finished on the reading thread
std::atomic<uint64_t> gAllocations{0};

/// Null when out of memory.
void* TryCountedAllocate(std::size_t inSize, std::size_t inAlignment) noexcept
{
    gAllocations.fetch_add(1, std::memory_order_relaxed);
    const std::size_t size = inSize == 0 ? 1 : inSize;
    return inAlignment > alignof(std::max_align_t)
               ? std::aligned_alloc(inAlignment, (size + inAlignment - 1) / inAlignment * inAlignment)
               : std::malloc(size);
}

void* CountedAllocate(std::size_t inSize, std::size_t inAlignment)
{
    void* memory = TryCountedAllocate(inSize, inAlignment);
    if (memory == nullptr) throw std::bad_alloc();
    return memory;
}
} // namespace

uint64_t cairn::test::GetAllocationCount()
{
    return gAllocations.load(std::memory_order_relaxed);
}

void* operator new(std::size_t inSize)
{
    return CountedAllocate(inSize, alignof(std::max_align_t));
}
void* operator new[](std::size_t inSize)
{
    return CountedAllocate(inSize, alignof(std::max_align_t));
}
void* operator new(std::size_t inSize, std::align_val_t inAlign)
{
    return CountedAllocate(inSize, std::size_t(inAlign));
}
void* operator new[](std::size_t inSize, std::align_val_t inAlign)
{
    return CountedAllocate(inSize, std::size_t(inAlign));
}
void operator delete(void* inMemory) noexcept
{
    std::free(inMemory);
}
void operator delete[](void* inMemory) noexcept
{
    std::free(inMemory);
}
void operator delete(void* inMemory, std::size_t) noexcept
{
    std::free(inMemory);
}
void operator delete[](void* inMemory, std::size_t) noexcept
{
    std::free(inMemory);
}
void operator delete(void* inMemory, std::align_val_t) noexcept
{
    std::free(inMemory);
}
void operator delete[](void* inMemory, std::align_val_t) noexcept
{
    std::free(inMemory);
}
void operator delete(void* inMemory, std::size_t, std::align_val_t) noexcept
{
    std::free(inMemory);
}
void operator delete[](void* inMemory, std::size_t, std::align_val_t) noexcept
{
    std::free(inMemory);
}
// The nothrow forms too: every form that a replaced delete (free) may release must come from malloc here, or
// AddressSanitizer, which intercepts the forms left alone, reports an alloc-dealloc mismatch
void* operator new(std::size_t inSize, const std::nothrow_t&) noexcept
{
    return TryCountedAllocate(inSize, alignof(std::max_align_t));
}
void* operator new[](std::size_t inSize, const std::nothrow_t&) noexcept
{
    return TryCountedAllocate(inSize, alignof(std::max_align_t));
}
void* operator new(std::size_t inSize, std::align_val_t inAlign, const std::nothrow_t&) noexcept
{
    return TryCountedAllocate(inSize, std::size_t(inAlign));
}
void* operator new[](std::size_t inSize, std::align_val_t inAlign, const std::nothrow_t&) noexcept
{
    return TryCountedAllocate(inSize, std::size_t(inAlign));
}
void operator delete(void* inMemory, const std::nothrow_t&) noexcept
{
    std::free(inMemory);
}
void operator delete[](void* inMemory, const std::nothrow_t&) noexcept
{
    std::free(inMemory);
}
void operator delete(void* inMemory, std::align_val_t, const std::nothrow_t&) noexcept
{
    std::free(inMemory);
}
void operator delete[](void* inMemory, std::align_val_t, const std::nothrow_t&) noexcept
{
    std::free(inMemory);
}
