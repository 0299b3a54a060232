#pragma once

// Result<T>: a value or an error with a message, for every call a user can get wrong.
// (std::expected is C++23; this is the subset Cairn needs.)

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace cairn::physics
{

enum class ErrorCode
{
    InvalidArgument, ///< NaN, infinity, out-of-range or otherwise malformed input
    DegenerateShape, ///< Zero/negative extents, coplanar hull points, empty mesh...
    InvalidBodyID,   ///< Unknown or stale body id
    AlreadyAdded,    ///< Body already in the world
    NotAdded,        ///< Body not in the world
    OutOfCapacity,   ///< A fixed-capacity pool is full
    WrongThread,     ///< Called from a thread that may not call it
    ParseError,      ///< A malformed file
    IOError,         ///< A file could not be read or written
};

const char* ToString(ErrorCode inCode);

struct Error
{
    ErrorCode mCode;
    std::string mMessage;
};

template <class T> class [[nodiscard]] Result
{
public:
    Result(T inValue) : mData(std::move(inValue)) {}
    Result(Error inError) : mData(std::move(inError)) {}

    bool IsOk() const { return mData.index() == 0; }
    explicit operator bool() const { return IsOk(); }

    const T& Value() const&
    {
        assert(IsOk());
        return std::get<0>(mData);
    }
    T& Value() &
    {
        assert(IsOk());
        return std::get<0>(mData);
    }
    T&& Value() &&
    {
        assert(IsOk());
        return std::get<0>(std::move(mData));
    }
    const Error& GetError() const
    {
        assert(!IsOk());
        return std::get<1>(mData);
    }

private:
    std::variant<T, Error> mData;
};

/// A status with no value: Ok or an error.
class [[nodiscard]] Status
{
public:
    Status() = default;
    Status(Error inError) : mError(std::move(inError)), mOk(false) {}
    static Status Ok() { return {}; }

    bool IsOk() const { return mOk; }
    explicit operator bool() const { return mOk; }
    const Error& GetError() const
    {
        assert(!mOk);
        return mError;
    }

private:
    Error mError{ErrorCode::InvalidArgument, {}};
    bool mOk = true;
};

inline Error MakeError(ErrorCode inCode, std::string inMessage)
{
    return Error{inCode, std::move(inMessage)};
}

} // namespace cairn::physics
