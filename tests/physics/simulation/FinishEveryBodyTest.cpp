// The finish (bounds, broad-phase move, published pose) of every active body, whichever way the solve
// reached it: a colored island that every thread solves, a group of small islands, an island with a joint, a
// body alone, a kinematic body, and a linear-cast body that its cast moved back. Each must publish the pose
// it ends the step with: a body left out publishes a stale pose (and never sleeps), and one finished before
// its cast publishes a pose it no longer has.

#include "SimulationFixture.h"
#include "cairn/physics/body/PublishedPose.h"
#include "cairn/physics/constraints/ConstraintInterface.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <array>
#include <vector>

namespace cairn::test
{
namespace
{

/// Every body the solve reaches by a different path, in one world:
struct MixedScene
{
    std::vector<BodyID> mBodies;    ///< Every body but the floor
    std::vector<BodyID> mLoneBoxes; ///< Resting alone: each an island of one manifold
    BodyID mKinematic;
};

/// Whether every body of inBodies has its pose published.
::testing::AssertionResult EveryPoseIsPublished(PhysicsSystem& ioSystem, const std::vector<BodyID>& inBodies)
{
    const PoseReader reader(ioSystem.GetBodyManager());
    BodyInterface& bodies = ioSystem.GetBodyInterface();
    for (const BodyID& id : inBodies)
    {
        PublishedPose pose;
        if (!reader.Read(id, pose))
            return ::testing::AssertionFailure() << "body " << id.GetIndex() << " unread";
        if (pose.mTransform.mPosition != bodies.GetPosition(id).Value() ||
            pose.mTransform.mRotation.coeffs() != bodies.GetRotation(id).Value().coeffs())
            return ::testing::AssertionFailure() << "body " << id.GetIndex() << " published a stale pose";
    }
    return ::testing::AssertionSuccess();
}

class FinishEveryBodyTest : public SimulationFixture
{
protected:
    /// A fresh world holding the mixed scene.
    MixedScene BuildMixedScene()
    {
        ResetWorld(PhysicsSettings());
        MixedScene scene;
        AddFloor();
        auto add = [&](const BodyCreationSettings& inSettings)
        {
            const BodyID id = AddDynamic(inSettings);
            scene.mBodies.push_back(id);
            return id;
        };
        const ShapeRef box = Box(Vec3(0.25f, 0.25f, 0.25f));
        // A stack of 150 boxes: one island of far more than a quarter of the step's constraints, colored and
        // solved by every thread
        for (int layer = 0; layer < 6; ++layer)
            for (int x = 0; x < 5; ++x)
                for (int z = 0; z < 5; ++z)
                    add(DynamicSettings(
                        box, Vec3(0.52f * float(x), 0.25f + 0.51f * float(layer), 0.52f * float(z))));
        // Boxes resting alone, far apart: islands of one manifold, solved four to a group
        for (int i = 0; i < 6; ++i)
            scene.mLoneBoxes.push_back(
                add(DynamicSettings(box, Vec3(10.0f + 2.0f * float(i), 0.25f, -10.0f))));
        // Two boxes hinged together: an island with a joint, solved whole by one thread
        HingeConstraintSettings hinge;
        hinge.mBodyA = add(DynamicSettings(box, Vec3(-10.0f, 1.0f, 10.0f)));
        hinge.mBodyB = add(DynamicSettings(box, Vec3(-9.4f, 1.0f, 10.0f)));
        hinge.mPoint = Vec3(-9.7f, 1.0f, 10.0f);
        hinge.mHingeAxis = Vec3(0, 0, 1);
        (void)System().GetConstraintInterface().AddHinge(hinge).Value();
        // Spheres falling from high up, touching nothing for a while: alone in their islands
        for (int i = 0; i < 4; ++i)
            add(DynamicSettings(Sphere(0.2f), Vec3(-10.0f + 1.0f * float(i), 20.0f, -10.0f)));
        // A kinematic body that is moved every step
        BodyCreationSettings kinematic = DynamicSettings(box, Vec3(10.0f, 2.0f, 10.0f));
        kinematic.mMotionType = MotionType::Kinematic;
        scene.mKinematic = add(kinematic);
        return scene;
    }

    /// Steps the mixed scene on inJobs (null: on this thread) and checks after every step that each body's
    /// published pose is its pose.
    void StepAndCheckEveryBody(jobs::JobInterface* inJobs)
    {
        const MixedScene scene = BuildMixedScene();
        uint32_t coloredSteps = 0;
        for (int step = 0; step < 90; ++step)
        {
            const float angle = 0.05f * float(step + 1);
            ASSERT_TRUE(Bodies()
                            .MoveKinematic(scene.mKinematic, Vec3(10.0f + std::sin(angle), 2.0f, 10.0f),
                                           Quat(Eigen::AngleAxisf(angle, Vec3::UnitY())), cDeltaTime)
                            .IsOk());
            const Status status =
                inJobs != nullptr ? System().Update(cDeltaTime, 1, *inJobs) : System().Update(cDeltaTime, 1);
            ASSERT_TRUE(status.IsOk());
            coloredSteps += System().GetLastStepStatistics().mNumColoredIslands > 0 ? 1 : 0;
            ASSERT_TRUE(EveryPoseIsPublished(System(), scene.mBodies)) << "after step " << step;
        }
        // Their sleep timers are kept by the finish
        for (const BodyID& id : scene.mLoneBoxes)
            EXPECT_FALSE(IsActive(id)) << "a box resting alone for 1.5 s should sleep";
        EXPECT_GT(coloredSteps, 0u) << "the stack was never a colored island: the scene misses that path";
    }
};

} // namespace

// A linear-cast body is finished after the casts: a spinning box flying obliquely at a wall of no thickness
// (two triangles) is moved back by its cast (the speculative contacts, made at the step's start, miss what
// its spin brings in), and publishes the pose the cast left it
TEST_F(FinishEveryBodyTest, ALinearCastBodyPublishesThePoseItsCastLeftIt)
{
    PhysicsSettings settings;
    settings.mGravity = Vec3::Zero();
    ResetWorld(settings);
    const Vec3 corners[] = {{0, -300, -300}, {0, 300, -300}, {0, 300, 300}, {0, -300, 300}};
    const std::array<uint32_t, 3> triangles[] = {{0, 2, 1}, {0, 3, 2}};
    AddStatic(TriangleMeshShape::Create(corners, triangles).Value(), Vec3::Zero());
    BodyCreationSettings body = DynamicSettings(Box(Vec3(0.1f, 0.1f, 0.1f)), Vec3(-1.0f, 0.0f, -1.0f));
    body.mLinearVelocity = 10.0f * Vec3(1, 0, 1).normalized();
    body.mAngularVelocity = Vec3(20.0f, 30.0f, 40.0f);
    body.mLinearDamping = 0.0f;
    body.mMotionQuality = MotionQuality::LinearCast;
    const std::vector<BodyID> ids{AddDynamic(body)};
    uint32_t movedBack = 0;
    for (int step = 0; step < 30; ++step)
    {
        ASSERT_TRUE(UpdateWorld(cDeltaTime).IsOk());
        movedBack += System().GetLastStepStatistics().mNumLinearCastsMovedBack;
        ASSERT_TRUE(EveryPoseIsPublished(System(), ids)) << "after step " << step;
    }
    EXPECT_GT(movedBack, 0u) << "the cast never moved the box back: the test misses what it is for";
}

TEST_F(FinishEveryBodyTest, EveryBodyPublishesItsFinalPoseOnOneThread)
{
    StepAndCheckEveryBody(nullptr);
}

TEST_F(FinishEveryBodyTest, EveryBodyPublishesItsFinalPoseForAnyThreadCount)
{
    for (uint32_t threads : {2u, 4u})
    {
        jobs::JobSystem::Settings settings;
        settings.mNumThreads = threads;
        jobs::JobSystem jobSystem(settings);
        SCOPED_TRACE(threads);
        StepAndCheckEveryBody(&jobSystem);
    }
}

} // namespace cairn::test
