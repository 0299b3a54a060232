#pragma once

// Buildings: the huts of the demo world. Four static walls around one room, a doorway in the front wall and
// a door in it: a dynamic panel hinged to the world at the doorway's edge, which swings into the room. The
// navmesh sees the door when it rests (a sleeping dynamic body is an obstacle) and not while it moves, so a
// door that opens or closes makes its tiles rebuild as it comes to rest, and a closed door shuts the room
// off from the paths outside it (Doors drives the doors and measures that).
//
// The room, in the building's frame (x across the front, +z into the room, y up; the origin at the middle of
// the floor): walls cBuildingHalfSize from the middle, a doorway cDoorwayHalfWidth either side of x = 0 in
// the front wall (z = -cBuildingHalfSize). The hinge is on the doorway's left edge (-x) at the wall's inner
// face, so the panel turns into the room clear of the wall's end; closed, it fills the doorway's inner side
// with cDoorGap to spare at either end.
//
// Threads: BuildingShapes is made once and then only read (its shapes are immutable); MakeBuilding works on
// its arguments alone: any thread.

#include "cairn/physics/body/BodyCreationSettings.h"
#include "cairn/physics/constraints/ConstraintInterface.h"
#include "cairn/physics/math/FunctionRef.h"

#include <numbers>
#include <vector>

namespace cairn::demo
{
using namespace cairn::physics;

inline constexpr float cBuildingHalfSize = 3.5f;  ///< m, outer: a 7 m square hut
inline constexpr float cWallThickness = 0.3f;     ///< m
inline constexpr float cWallHeight = 3.6f;        ///< m, of which cWallSunk below the lowest ground
inline constexpr float cWallSunk = 0.4f;          ///< m
inline constexpr float cDoorwayHalfWidth = 1.2f;  ///< m: a human agent (0.6 m radius) passes, a large one not
inline constexpr float cDoorGap = 0.05f;          ///< m between the panel and each side of the doorway
inline constexpr float cDoorHeight = 2.2f;        ///< m
inline constexpr float cDoorThickness = 0.1f;     ///< m
inline constexpr float cDoorDensity = 100.0f;     ///< kg/m^3: a 50 kg wooden door
inline constexpr float cDoorMotorTorque = 500.0f; ///< N m: opens against its 90 kg m^2 in about a second
/// The hinge's angle of an open door (into the room) and the limits' slack beyond open and closed, rad
inline constexpr float cDoorOpenAngle = -0.5f * std::numbers::pi_v<float>;
inline constexpr float cDoorLimitSlack = 0.1f;
/// How far DoorSpec's ground points lie out of the doorway's middle and into the room (m)
inline constexpr float cDoorOutsideDistance = 1.5f;
inline constexpr float cDoorInsideDistance = 1.8f;
/// The footprint circle that keeps other props out of the hut and off its walls
inline constexpr float cBuildingFootprintRadius = 1.4143f * cBuildingHalfSize;
/// The most the ground may rise across a hut's square (m): the walls' fixed height covers it, and the gap
/// under the door stays small
inline constexpr float cBuildingMaxGroundRise = 0.6f;

/// A hut's door: its panel, its hinge, and two ground points a path through the doorway joins.
struct DoorSpec
{
    BodyCreationSettings mPanel;    ///< Dynamic, closed (the hinge's angle 0)
    HingeConstraintSettings mHinge; ///< To the world, its motor holding it closed; mBodyB set once created
    Vec3 mOutside = Vec3::Zero();   ///< On the ground, cDoorOutsideDistance out of the doorway's middle
    Vec3 mInside = Vec3::Zero();    ///< On the ground, cDoorInsideDistance into the room from there
    float mPeriod = 12.0f; ///< s: the door opens for half of each period and closes for the other half
    float mPhase = 0.0f;   ///< s, into its period at time 0
};

/// A door's motor: a position motor that swings it open (into the room) or closed and holds it there.
MotorSettings DoorMotor(bool inOpen);

/// The shapes every hut shares.
struct BuildingShapes
{
    BuildingShapes();
    ShapeRef mSideWall;  ///< The back and the two side walls
    ShapeRef mFrontWall; ///< One of the two pieces either side of the doorway
    ShapeRef mPanel;
};

/// Where a hut stands: its middle on the x-z plane (world), the yaw's cosine and sine (the building's +x is
/// (cos, 0, -sin) in the world, as a rotation about +y by the yaw), and a height function of world x, z.
struct BuildingSite
{
    float mX = 0.0f;
    float mZ = 0.0f;
    float mCos = 1.0f;
    float mSin = 0.0f;
    Quat mRotation = Quat::Identity(); ///< The same yaw
};

/// The lowest and highest ground under a hut's square (sampled every metre and at its corners).
void GroundRange(const BuildingSite& inSite, FunctionRef<float(float, float)> inGround, float& outLowest,
                 float& outHighest);

/// Appends the hut's walls (static, in inWallLayer) to ioWalls and returns its door. The walls stand
/// cWallSunk below inLowest; the door's bottom clears the highest ground its swing covers.
DoorSpec MakeBuilding(const BuildingShapes& inShapes, const BuildingSite& inSite,
                      FunctionRef<float(float, float)> inGround, float inLowest, float inFriction,
                      std::vector<BodyCreationSettings>& ioWalls);

} // namespace cairn::demo
