#pragma once

// FunctionRef: a non-owning reference to a callable, so callbacks in hot paths never allocate
// (std::function may). The referenced callable must outlive the call it is passed to.

#include <type_traits>
#include <utility>

namespace cairn::physics
{

template <class Signature> class FunctionRef;

template <class R, class... Args> class FunctionRef<R(Args...)>
{
public:
    template <class F>
    requires(!std::is_same_v<std::remove_cvref_t<F>, FunctionRef> && std::is_invocable_r_v<R, F&, Args...>)
        FunctionRef(F&& inCallable) // NOLINT: implicit by design, like std::function
        : mObject(const_cast<void*>(static_cast<const void*>(&inCallable))),
          mInvoke(
              [](void* inObject, Args... inArgs) -> R {
                  return (*static_cast<std::remove_reference_t<F>*>(inObject))(std::forward<Args>(inArgs)...);
              })
    {
    }

    R operator()(Args... inArgs) const { return mInvoke(mObject, std::forward<Args>(inArgs)...); }

private:
    void* mObject;
    R (*mInvoke)(void*, Args...);
};

} // namespace cairn::physics
