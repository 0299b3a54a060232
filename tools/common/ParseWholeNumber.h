#pragma once

// A command-line or file field as an unsigned whole number, all of it: std::from_chars takes no sign, blank
// or prefix for an unsigned type and refuses values past its range, where sscanf's %u and CLI11 read "-1" as
// the type's maximum.

#include <charconv>
#include <string_view>
#include <type_traits>

namespace cairn::tools
{
using namespace cairn::physics;

template <class T> bool ParseWholeNumber(std::string_view inText, T& outValue)
{
    static_assert(std::is_unsigned_v<T>, "digits only: a signed type would take a minus sign");
    T value{};
    const auto [end, error] = std::from_chars(inText.data(), inText.data() + inText.size(), value);
    if (error != std::errc() || end != inText.data() + inText.size()) return false;
    outValue = value;
    return true;
}

} // namespace cairn::tools
