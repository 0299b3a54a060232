#include "cairn/physics/math/Result.h"

namespace cairn::physics
{

const char* ToString(ErrorCode inCode)
{
    switch (inCode)
    {
    case ErrorCode::InvalidArgument:
        return "invalid argument";
    case ErrorCode::DegenerateShape:
        return "degenerate shape";
    case ErrorCode::InvalidBodyID:
        return "invalid body id";
    case ErrorCode::AlreadyAdded:
        return "body already added";
    case ErrorCode::NotAdded:
        return "body not added";
    case ErrorCode::OutOfCapacity:
        return "out of capacity";
    case ErrorCode::WrongThread:
        return "wrong thread";
    case ErrorCode::ParseError:
        return "parse error";
    case ErrorCode::IOError:
        return "I/O error";
    }
    return "unknown error";
}

} // namespace cairn::physics
