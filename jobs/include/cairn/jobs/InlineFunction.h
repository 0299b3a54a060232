#pragma once

// InlineFunction: a move-only void() callable stored in a fixed buffer inside the object, so that scheduling
// a job never touches the heap (a warm physics step allocates nothing). A callable that does not fit is a
// compile-time error: capture by reference or pass a pointer to bigger state.
//
// Threads: an InlineFunction is owned by one thread at a time (the job system hands a job's function from the
// scheduling thread to the running one through its queue, which orders the accesses).

#include <cstddef>
#include <new>
#include <type_traits>
#include <utility>

namespace cairn::jobs
{

template <size_t Capacity> class InlineFunction
{
public:
    InlineFunction() = default;
    InlineFunction(const InlineFunction&) = delete;
    InlineFunction& operator=(const InlineFunction&) = delete;
    ~InlineFunction() { Reset(); }

    /// Stores inFunction (moved or copied in); replaces what was stored.
    template <class Function> void Set(Function&& inFunction)
    {
        using Stored = std::decay_t<Function>;
        static_assert(sizeof(Stored) <= Capacity, "job function too large: capture by reference or pointer");
        static_assert(alignof(Stored) <= alignof(std::max_align_t), "job function over-aligned");
        static_assert(std::is_invocable_r_v<void, Stored&>, "a job function takes no arguments");
        Reset();
        ::new (static_cast<void*>(mStorage)) Stored(std::forward<Function>(inFunction));
        mInvoke = [](void* inStorage) { (*std::launder(static_cast<Stored*>(inStorage)))(); };
        mDestroy = [](void* inStorage) { std::launder(static_cast<Stored*>(inStorage))->~Stored(); };
    }

    bool IsSet() const { return mInvoke != nullptr; }
    void operator()() { mInvoke(mStorage); }

    /// Destroys the stored callable (its captures are released here, not when the slot is reused).
    void Reset()
    {
        if (mDestroy != nullptr) mDestroy(mStorage);
        mInvoke = nullptr;
        mDestroy = nullptr;
    }

private:
    alignas(std::max_align_t) unsigned char mStorage[Capacity];
    void (*mInvoke)(void*) = nullptr;
    void (*mDestroy)(void*) = nullptr;
};

} // namespace cairn::jobs
