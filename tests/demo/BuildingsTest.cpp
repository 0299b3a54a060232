// The demo world's huts (Buildings.h): every door of a few tiles of the default world, in a world with its
// tile's terrain and props, swings fully open into its room and shut again on its motor, and rests there: no
// wall end, no prop and no rise of the ground catches it.

#include "Buildings.h"

#include "WorldGenerator.h"
#include "cairn/physics/PhysicsSystem.h"
#include "common/MakePhysicsSystem.h"

#include <cmath>
#include <gtest/gtest.h>
#include <string>

namespace cairn::demo
{
namespace
{
using namespace cairn::physics;

struct Door
{
    BodyID mPanel;
    ConstraintID mHinge;
};

/// Steps until every door sleeps; false after inMaxFrames.
bool StepUntilAllRest(PhysicsSystem& ioPhysics, const std::vector<Door>& inDoors, int inMaxFrames)
{
    for (int frame = 0; frame < inMaxFrames; ++frame)
    {
        bool anyAwake = false;
        for (const Door& door : inDoors)
            anyAwake = anyAwake || ioPhysics.GetBodyInterface().IsActive(door.mPanel).Value();
        if (!anyAwake) return true;
        if (!ioPhysics.Update(1.0f / 60.0f).IsOk()) return false;
    }
    return false;
}

TEST(BuildingsTest, EveryDoorSwingsOpenAndShutOnItsMotorAndRestsThere)
{
    PhysicsSettings settings;
    settings.mMaxBodies = 8192;
    const std::unique_ptr<PhysicsSystem> physics = cairn::test::MakePhysicsSystem(settings);
    BodyInterface& bodies = physics->GetBodyInterface();
    ConstraintInterface& joints = physics->GetConstraintInterface();
    const WorldGenerator generator(WorldSettings{}); // The demo's default world: two huts a tile
    std::vector<Door> doors;
    for (const WorldTile tile : {WorldTile{0, 0}, WorldTile{1, 0}, WorldTile{0, 1}, WorldTile{-1, -1}})
    {
        TileContent content = generator.GenerateTile(tile, false);
        EXPECT_EQ(content.mDoors.size(), 2u) << "tile " << tile.mX << ", " << tile.mZ;
        ASSERT_TRUE(bodies.CreateAndAddBody(content.mTerrain, Activation::DontActivate));
        for (const BodyCreationSettings& prop : content.mProps)
            ASSERT_TRUE(bodies.CreateAndAddBody(prop, Activation::DontActivate));
        for (DoorSpec& spec : content.mDoors)
        {
            Door door;
            door.mPanel = bodies.CreateAndAddBody(spec.mPanel, Activation::DontActivate).Value();
            spec.mHinge.mBodyB = door.mPanel;
            Result<ConstraintID> hinge = joints.AddHinge(spec.mHinge);
            ASSERT_TRUE(hinge) << hinge.GetError().mMessage;
            door.mHinge = hinge.Value();
            doors.push_back(door);
        }
    }
    ASSERT_FALSE(doors.empty());

    // Made closed, held closed: nothing pushes a panel out of its doorway
    ASSERT_TRUE(StepUntilAllRest(*physics, doors, 600)) << "a door did not come to rest where it was made";
    for (size_t i = 0; i < doors.size(); ++i)
        EXPECT_NEAR(joints.GetPosition(doors[i].mHinge).Value(), 0.0f, 0.05f) << "door " << i;

    for (const bool open : {true, false, true})
    {
        SCOPED_TRACE(open ? "opening" : "closing");
        for (const Door& door : doors)
            ASSERT_TRUE(joints.SetMotor(door.mHinge, DoorMotor(open)).IsOk());
        ASSERT_TRUE(StepUntilAllRest(*physics, doors, 900)) << "a door did not come to rest";
        for (size_t i = 0; i < doors.size(); ++i)
            EXPECT_NEAR(joints.GetPosition(doors[i].mHinge).Value(), open ? cDoorOpenAngle : 0.0f, 0.05f)
                << "door " << i;
    }
}

} // namespace
} // namespace cairn::demo
