#pragma once

// An allocator whose construct() without arguments leaves the new element's bytes as they are, for arrays
// that are grown and then overwritten element by element before anything reads them: the contact cache's
// 184-byte manifolds, 8,000 of them a step in a pyramid, grown on the updating thread and filled by the
// merge's parallel copies. Value-initialisation zeroed them and default-initialisation still ran their
// member initialisers: either way the updating thread wrote 1.5 MB (a cache miss per line) that the copies
// then overwrote. Only for implicit-lifetime types (aggregates whose destructor is not user-provided, C++20
// [class.prop]): storage from allocate() then holds such an object without a constructor call. Other types
// are default-initialised. Everything else is std::allocator.

#include <memory>
#include <new>
#include <type_traits>
#include <utility>

namespace cairn::physics
{

template <class T> class UninitializedAllocator : public std::allocator<T>
{
public:
    using std::allocator<T>::allocator;
    template <class U> struct rebind
    {
        using other = UninitializedAllocator<U>;
    };

    template <class U> void construct(U* inPlace) noexcept(std::is_nothrow_default_constructible_v<U>)
    {
        if constexpr (!(std::is_aggregate_v<U> && std::is_trivially_destructible_v<U>))
            ::new (static_cast<void*>(inPlace)) U;
    }
    template <class U, class... Args> void construct(U* inPlace, Args&&... inArgs)
    {
        ::new (static_cast<void*>(inPlace)) U(std::forward<Args>(inArgs)...);
    }
};

} // namespace cairn::physics
