#pragma once

// An allocator whose construct() without arguments default-initialises (new (p) T) instead of
// value-initialising (new (p) T()): std::vector::resize then runs only T's own initialisers and does not zero
// the whole object first. For arrays that are grown and then filled, where the zeroing was pure cost (the
// contact cache's 176-byte manifolds, 7,000 of them a step in a pyramid). Everything else is std::allocator.

#include <memory>
#include <new>
#include <type_traits>
#include <utility>

namespace cairn
{

template <class T> class DefaultInitAllocator : public std::allocator<T>
{
public:
    using std::allocator<T>::allocator;
    template <class U> struct rebind
    {
        using other = DefaultInitAllocator<U>;
    };

    template <class U> void construct(U* inPlace) noexcept(std::is_nothrow_default_constructible_v<U>)
    {
        ::new (static_cast<void*>(inPlace)) U;
    }
    template <class U, class... Args> void construct(U* inPlace, Args&&... inArgs)
    {
        ::new (static_cast<void*>(inPlace)) U(std::forward<Args>(inArgs)...);
    }
};

} // namespace cairn
