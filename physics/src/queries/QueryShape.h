#pragma once

// Which shapes a world query (and a character) can sweep or collide with every body.

#include "cairn/physics/shapes/CompoundShape.h"

namespace cairn::physics
{

/// Whether the narrow phase can collide inShape with any body: convex shapes and compounds of them. A
/// triangle mesh or height field collides only with convex shapes, so against a mesh body it would answer
/// "clear".
inline bool CanBeQueryShape(const Shape& inShape)
{
    if (inShape.IsConvex()) return true;
    if (inShape.GetType() != ShapeType::Compound) return false;
    for (const CompoundShape::SubShape& child : static_cast<const CompoundShape&>(inShape).GetSubShapes())
        if (!CanBeQueryShape(*child.mShape)) return false;
    return true;
}

} // namespace cairn::physics
