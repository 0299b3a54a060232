// Buildings: a hut's walls and door from its site (see Buildings.h).

#include "Buildings.h"

#include "cairn/physics/shapes/BoxShape.h"

#include <algorithm>
#include <cmath>

namespace cairn::demo
{
using namespace cairn::physics;

namespace
{
/// Building frame (x, z) to world (x, z): the yaw's rotation about +y, then the site's middle
void ToWorld(const BuildingSite& inSite, float inX, float inZ, float& outX, float& outZ)
{
    outX = inSite.mX + inX * inSite.mCos + inZ * inSite.mSin;
    outZ = inSite.mZ - inX * inSite.mSin + inZ * inSite.mCos;
}

Vec3 WorldPoint(const BuildingSite& inSite, float inX, float inY, float inZ)
{
    float x, z;
    ToWorld(inSite, inX, inZ, x, z);
    return Vec3(x, inY, z);
}

ShapeRef Box(float inX, float inY, float inZ)
{
    // Cannot fail: constant, positive half extents; a null shape would make CreateBody refuse the wall
    auto box = BoxShape::Create(Vec3(inX, inY, inZ));
    return box ? ShapeRef(std::move(box).Value()) : ShapeRef();
}

/// The lowest and highest ground over a rectangle of the building frame, sampled every inSpacing or closer,
/// its edges included
void SampleGround(const BuildingSite& inSite, FunctionRef<float(float, float)> inGround, float inX0,
                  float inZ0, float inX1, float inZ1, float inSpacing, float& outLowest, float& outHighest)
{
    outLowest = cLargeFloat;
    outHighest = -cLargeFloat;
    const int nx = int(std::ceil((inX1 - inX0) / inSpacing)), nz = int(std::ceil((inZ1 - inZ0) / inSpacing));
    for (int i = 0; i <= nz; ++i)
        for (int j = 0; j <= nx; ++j)
        {
            float x, z;
            ToWorld(inSite, inX0 + (inX1 - inX0) * float(j) / float(nx),
                    inZ0 + (inZ1 - inZ0) * float(i) / float(nz), x, z);
            const float h = inGround(x, z);
            outLowest = std::min(outLowest, h);
            outHighest = std::max(outHighest, h);
        }
}
} // namespace

MotorSettings DoorMotor(bool inOpen)
{
    MotorSettings motor;
    motor.mMode = MotorMode::Position;
    motor.mTargetPosition = inOpen ? cDoorOpenAngle : 0.0f;
    motor.mMaxForce = cDoorMotorTorque;
    return motor; // The default spring: 2 Hz, critically damped, so it stops without a bounce
}

BuildingShapes::BuildingShapes()
    : mSideWall(Box(cBuildingHalfSize, 0.5f * cWallHeight, 0.5f * cWallThickness)),
      mFrontWall(
          Box(0.5f * (cBuildingHalfSize - cDoorwayHalfWidth), 0.5f * cWallHeight, 0.5f * cWallThickness)),
      mPanel(Box(cDoorwayHalfWidth - cDoorGap, 0.5f * cDoorHeight, 0.5f * cDoorThickness))
{
}

void GroundRange(const BuildingSite& inSite, FunctionRef<float(float, float)> inGround, float& outLowest,
                 float& outHighest)
{
    SampleGround(inSite, inGround, -cBuildingHalfSize, -cBuildingHalfSize, cBuildingHalfSize,
                 cBuildingHalfSize, 1.0f, outLowest, outHighest);
}

DoorSpec MakeBuilding(const BuildingShapes& inShapes, const BuildingSite& inSite,
                      FunctionRef<float(float, float)> inGround, float inLowest, float inFriction,
                      std::vector<BodyCreationSettings>& ioWalls)
{
    const float wallY = inLowest - cWallSunk + 0.5f * cWallHeight;
    const float inner = cBuildingHalfSize - cWallThickness; // The walls' inner faces, from the middle
    const float mid = cBuildingHalfSize - 0.5f * cWallThickness;
    // A quarter turn about +y: the side walls are the back wall turned
    const Quat quarter(std::sqrt(0.5f), 0.0f, std::sqrt(0.5f), 0.0f);
    auto wall = [&](const ShapeRef& inShape, float inX, float inZ, bool inTurned)
    {
        BodyCreationSettings settings;
        settings.mShape = inShape;
        settings.mPosition = WorldPoint(inSite, inX, wallY, inZ);
        settings.mRotation = inTurned ? (inSite.mRotation * quarter).normalized() : inSite.mRotation;
        settings.mMotionType = MotionType::Static;
        settings.mObjectLayer = Layers::cStatic;
        settings.mFriction = inFriction;
        ioWalls.push_back(std::move(settings));
    };
    wall(inShapes.mSideWall, 0.0f, mid, false);
    wall(inShapes.mSideWall, -mid, 0.0f, true);
    wall(inShapes.mSideWall, mid, 0.0f, true);
    const float frontX = 0.5f * (cBuildingHalfSize + cDoorwayHalfWidth);
    wall(inShapes.mFrontWall, -frontX, -mid, false);
    wall(inShapes.mFrontWall, frontX, -mid, false);

    // The door clears the highest ground its swing covers: the quarter disc from the hinge into the room
    const float reach = 2.0f * cDoorwayHalfWidth;
    float lowest, highest;
    SampleGround(inSite, inGround, -cDoorwayHalfWidth, -inner - cDoorThickness, cDoorwayHalfWidth,
                 -inner + reach, 0.5f, lowest, highest);
    const float bottom = highest + 0.03f;
    DoorSpec door;
    door.mPanel.mShape = inShapes.mPanel;
    door.mPanel.mPosition =
        WorldPoint(inSite, 0.0f, bottom + 0.5f * cDoorHeight, -inner - 0.5f * cDoorThickness);
    door.mPanel.mRotation = inSite.mRotation;
    door.mPanel.mMotionType = MotionType::Dynamic;
    door.mPanel.mObjectLayer = Layers::cMoving;
    door.mPanel.mDensity = cDoorDensity;
    door.mPanel.mFriction = inFriction;
    door.mHinge.mPoint = WorldPoint(inSite, -cDoorwayHalfWidth, bottom + 0.5f * cDoorHeight, -inner);
    door.mHinge.mHingeAxis = Vec3(0.0f, 1.0f, 0.0f);
    door.mHinge.mLimitsMin = cDoorOpenAngle - cDoorLimitSlack;
    door.mHinge.mLimitsMax = cDoorLimitSlack;
    door.mHinge.mMotor = DoorMotor(false);
    float x, z;
    ToWorld(inSite, 0.0f, -cBuildingHalfSize - cDoorOutsideDistance, x, z);
    door.mOutside = Vec3(x, inGround(x, z), z);
    ToWorld(inSite, 0.0f, -inner + cDoorInsideDistance, x, z);
    door.mInside = Vec3(x, inGround(x, z), z);
    return door;
}

} // namespace cairn::demo
