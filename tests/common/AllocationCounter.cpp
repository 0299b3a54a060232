#include "common/AllocationCounter.h"

#include <cstddef>
#include <cstdlib>
#include <new>

namespace
{
// Relaxed: a statistic read after the counted work has been joined or finished on the reading thread
std::atomic<uint64_t> gAllocations{0};

void* CountedAllocate(std::size_t inSize, std::size_t inAlignment)
{
    gAllocations.fetch_add(1, std::memory_order_relaxed);
    const std::size_t size = inSize == 0 ? 1 : inSize;
    void* memory = inAlignment > alignof(std::max_align_t)
                       ? std::aligned_alloc(inAlignment, (size + inAlignment - 1) / inAlignment * inAlignment)
                       : std::malloc(size);
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
