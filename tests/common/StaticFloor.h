#pragma once

// The static box floor that many step tests stand their bodies on (its top face at y = 0), and the box bodies
// they stand there.

#include "cairn/physics/body/BodyCreationSettings.h"
#include "cairn/physics/body/Layers.h"
#include "cairn/physics/shapes/BoxShape.h"

namespace cairn::test
{
using namespace cairn::physics;

/// Settings of a static floor 2 m thick whose top is at y = 0, reaching inHalfWidth metres from the origin
/// along x and z.
inline BodyCreationSettings StaticFloorSettings(float inHalfWidth)
{
    BodyCreationSettings floor;
    floor.mShape = BoxShape::Create(Vec3(inHalfWidth, 1.0f, inHalfWidth)).Value();
    floor.mPosition = Vec3(0.0f, -1.0f, 0.0f);
    floor.mMotionType = MotionType::Static;
    floor.mObjectLayer = Layers::cStatic;
    return floor;
}

/// Settings of a box body of any motion type, in the static layer when static and the moving one otherwise.
inline BodyCreationSettings BoxBodySettings(const Vec3& inCenter, const Vec3& inHalfExtent,
                                            MotionType inMotion)
{
    BodyCreationSettings settings;
    settings.mShape = BoxShape::Create(inHalfExtent).Value();
    settings.mPosition = inCenter;
    settings.mMotionType = inMotion;
    settings.mObjectLayer = inMotion == MotionType::Static ? Layers::cStatic : Layers::cMoving;
    return settings;
}

} // namespace cairn::test
