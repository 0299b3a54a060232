// A wall with a door: the path goes through the door; a box dropped into the doorway (dynamic, then asleep,
// an obstacle) makes its tiles dirty, they are rebuilt in the background, and then no path gets through;
// removing the box brings the path back. A hinged door driven by its motor does the same: closed and at
// rest it blocks the path, swung open and at rest it lets it through, its tiles rebuilt each time it stops.

#include "NavMeshSceneFixture.h"
#include "cairn/physics/constraints/ConstraintInterface.h"
#include "common/StaticFloor.h"

#include <numbers>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

class DoorSceneTest : public NavMeshSceneFixture
{
protected:
    void BuildRoom()
    {
        AddStaticBox(Vec3(0, -0.5f, 0), Vec3(10, 0.5f, 10)); // Floor, top at y = 0
        // A wall along x at z = 0, 3 m high, with a 2 m door in the middle (x in [-1, 1])
        AddStaticBox(Vec3(-5.5f, 1.5f, 0), Vec3(4.5f, 1.5f, 0.2f));
        AddStaticBox(Vec3(5.5f, 1.5f, 0), Vec3(4.5f, 1.5f, 0.2f));
        MakeNavMesh();
    }

    Result<PathResult> PathAcross() const { return mWorld->FindPath(Vec3(0.5f, 0, -6), Vec3(-0.5f, 0, 6)); }

    /// Every point of the path is within the doorway where it crosses the wall.
    static bool GoesThroughDoor(const PathResult& inPath)
    {
        for (size_t i = 0; i + 1 < inPath.mStraightPath.size(); ++i)
        {
            const Vec3& a = inPath.mStraightPath[i];
            const Vec3& b = inPath.mStraightPath[i + 1];
            if ((a.z() < 0) == (b.z() < 0)) continue;
            const float t = a.z() / (a.z() - b.z());
            const float x = a.x() + t * (b.x() - a.x());
            if (std::abs(x) > 1.0f) return false;
        }
        return true;
    }
};

TEST_F(DoorSceneTest, BoxInTheDoorwayBlocksThePathUntilRemoved)
{
    BuildRoom();
    ASSERT_TRUE(RunUntilIdle());
    EXPECT_EQ(mWorld->GetNumTiles(), 4); // The room spans the four tiles around the origin

    Result<PathResult> open = PathAcross();
    ASSERT_TRUE(open) << open.GetError().mMessage;
    EXPECT_TRUE(open.Value().mReachedEnd);
    EXPECT_TRUE(GoesThroughDoor(open.Value()));
    EXPECT_GE(open.Value().mStraightPath.size(), 2u);

    // Dropped into the doorway: 1.2 m wide, 1.5 m high (too high to climb), falls 0.5 m and goes to sleep
    const BodyID box = AddDynamicBox(Vec3(0, 1.25f, 0), Vec3(0.6f, 0.75f, 0.18f));
    int frames = 0;
    while (mPhysics->GetBodyInterface().IsActive(box).Value() && frames < 600)
    {
        Frame();
        ++frames;
    }
    ASSERT_FALSE(mPhysics->GetBodyInterface().IsActive(box).Value()) << "the box did not fall asleep";
    const uint64_t rebuildsBefore = mScheduler->GetStats().mRebuilds;
    ASSERT_TRUE(RunUntilIdle());
    EXPECT_GT(mScheduler->GetStats().mRebuilds, rebuildsBefore); // Its tiles were dirty and built again

    Result<PathResult> blocked = PathAcross();
    ASSERT_TRUE(blocked) << blocked.GetError().mMessage;
    EXPECT_FALSE(blocked.Value().mReachedEnd);

    ASSERT_TRUE(mPhysics->GetBodyInterface().RemoveBody(box).IsOk());
    ASSERT_TRUE(RunUntilIdle());
    Result<PathResult> reopened = PathAcross();
    ASSERT_TRUE(reopened) << reopened.GetError().mMessage;
    EXPECT_TRUE(reopened.Value().mReachedEnd);
    EXPECT_TRUE(GoesThroughDoor(reopened.Value()));
}

TEST_F(DoorSceneTest, AHingedDoorBlocksThePathWhenItStopsClosedAndFreesItWhenItStopsOpen)
{
    BuildRoom();
    ASSERT_TRUE(RunUntilIdle());
    // The door: a panel over the doorway (x in [-1, 1]) just off the wall's +z face and a few centimetres off
    // the floor, hinged to the world at its edge x = -1 about the vertical, its motor holding it closed. It
    // opens away from the wall (a negative angle), so that no part of it swings into the wall
    BodyCreationSettings panel =
        cairn::test::BoxBodySettings(Vec3(0.0f, 1.25f, 0.3f), Vec3(1.0f, 1.2f, 0.05f), MotionType::Dynamic);
    panel.mDensity = 100.0f; // A wooden door's 48 kg
    const BodyID door = mPhysics->GetBodyInterface().CreateAndAddBody(panel, Activation::Activate).Value();
    HingeConstraintSettings hinge;
    hinge.mBodyB = door;
    hinge.mPoint = Vec3(-1.0f, 1.25f, 0.3f);
    hinge.mHingeAxis = Vec3(0.0f, 1.0f, 0.0f);
    hinge.mLimitsMin = -0.5f * std::numbers::pi_v<float> - 0.1f;
    hinge.mLimitsMax = 0.1f;
    hinge.mMotor.mMode = MotorMode::Position;
    hinge.mMotor.mTargetPosition = 0.0f;
    hinge.mMotor.mMaxForce = 500.0f;
    ConstraintInterface& joints = mPhysics->GetConstraintInterface();
    const ConstraintID joint = joints.AddHinge(hinge).Value();

    // Frames until the door sleeps (its motor brought it to rest), then until its tiles are built again
    const auto settle = [&]
    {
        int frames = 0;
        while (mPhysics->GetBodyInterface().IsActive(door).Value() && frames < 1200)
        {
            Frame();
            ++frames;
        }
        ASSERT_FALSE(mPhysics->GetBodyInterface().IsActive(door).Value()) << "the door did not come to rest";
        // It fell asleep in the last Frame's step, before that Frame's scheduler Update
        const uint64_t restFrame = mScheduler->GetFrame();
        const uint64_t rebuildsBefore = mScheduler->GetStats().mRebuilds;
        ASSERT_TRUE(RunUntilIdle());
        EXPECT_GT(mScheduler->GetStats().mRebuilds, rebuildsBefore); // Its tiles were dirty and built again
        // Each tile the door stands in was published from a build started once it was at rest
        std::vector<TileCoord> tiles;
        ASSERT_TRUE(mWorld->GetGrid().TilesOverlapping(
            mPhysics->GetBodyInterface().GetWorldBounds(door).Value(), 0.0f, tiles));
        ASSERT_FALSE(tiles.empty());
        for (const TileCoord& tile : tiles)
        {
            const std::optional<TileScheduler::Publication> publication =
                mScheduler->GetLastPublication(tile);
            ASSERT_TRUE(publication.has_value());
            EXPECT_GE(publication->mBuildStartFrame, restFrame);
            EXPECT_GE(publication->mPublishFrame, publication->mBuildStartFrame);
        }
    };

    settle();
    EXPECT_NEAR(joints.GetPosition(joint).Value(), 0.0f, 0.05f);
    Result<PathResult> closed = PathAcross();
    ASSERT_TRUE(closed) << closed.GetError().mMessage;
    EXPECT_FALSE(closed.Value().mReachedEnd);

    // Opened by its motor (on a timer, in a game): a quarter turn, the panel along the wall's normal at x =
    // -1
    MotorSettings open = hinge.mMotor;
    open.mTargetPosition = -0.5f * std::numbers::pi_v<float>;
    ASSERT_TRUE(joints.SetMotor(joint, open).IsOk());
    settle();
    EXPECT_NEAR(joints.GetPosition(joint).Value(), open.mTargetPosition, 0.05f);
    Result<PathResult> opened = PathAcross();
    ASSERT_TRUE(opened) << opened.GetError().mMessage;
    EXPECT_TRUE(opened.Value().mReachedEnd);
    EXPECT_TRUE(GoesThroughDoor(opened.Value()));

    // And closed again
    ASSERT_TRUE(joints.SetMotor(joint, hinge.mMotor).IsOk());
    settle();
    Result<PathResult> closedAgain = PathAcross();
    ASSERT_TRUE(closedAgain) << closedAgain.GetError().mMessage;
    EXPECT_FALSE(closedAgain.Value().mReachedEnd);
}

TEST_F(DoorSceneTest, AnAwakeBoxIsNotAnObstacle)
{
    BuildRoom();
    ASSERT_TRUE(RunUntilIdle());
    // A box in the doorway that never sleeps: it may move at any time, so it is not in the navmesh, even
    // when its tiles are rebuilt
    BodyCreationSettings settings =
        cairn::test::BoxBodySettings(Vec3(0, 0.75f, 0), Vec3(0.6f, 0.75f, 0.18f), MotionType::Dynamic);
    settings.mAllowSleeping = false;
    const BodyID box = mPhysics->GetBodyInterface().CreateAndAddBody(settings, Activation::Activate).Value();
    mScheduler->MarkDirty(AABB(Vec3(-1, 0, -1), Vec3(1, 3, 1)));
    ASSERT_TRUE(RunUntilIdle());
    ASSERT_TRUE(mPhysics->GetBodyInterface().IsActive(box).Value());
    Result<PathResult> path = PathAcross();
    ASSERT_TRUE(path);
    EXPECT_TRUE(path.Value().mReachedEnd);
}

TEST_F(DoorSceneTest, TriggersAndDebrisAreIgnored)
{
    BuildRoom();
    // A sensor volume filling the doorway, and sleeping debris in it: neither is something agents walk around
    BodyCreationSettings trigger;
    trigger.mShape = BoxShape::Create(Vec3(1.0f, 1.5f, 0.2f)).Value();
    trigger.mPosition = Vec3(0, 1.5f, 0);
    trigger.mMotionType = MotionType::Static;
    trigger.mObjectLayer = Layers::cTrigger;
    ASSERT_TRUE(mPhysics->GetBodyInterface().CreateAndAddBody(trigger, Activation::DontActivate));
    BodyCreationSettings debris;
    debris.mShape = BoxShape::Create(Vec3(0.9f, 0.75f, 0.18f)).Value();
    debris.mPosition = Vec3(0, 0.75f, 0);
    debris.mMotionType = MotionType::Dynamic;
    debris.mObjectLayer = Layers::cDebris;
    ASSERT_TRUE(mPhysics->GetBodyInterface().CreateAndAddBody(debris, Activation::DontActivate));
    mScheduler->MarkDirty(AABB(Vec3(-1, 0, -1), Vec3(1, 3, 1)));
    ASSERT_TRUE(RunUntilIdle());
    Result<PathResult> path = PathAcross();
    ASSERT_TRUE(path);
    EXPECT_TRUE(path.Value().mReachedEnd);
}

} // namespace
} // namespace cairn::navmesh::test
