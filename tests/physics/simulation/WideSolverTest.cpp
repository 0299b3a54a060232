// The wide solver (four manifolds per SSE register, for colored islands) does the scalar solver's arithmetic
// in the same order: the same scene gives the same body states either way, step after step. The same for an
// island's coloring and solve order taken over from the previous step (SolverSettings::mReuseColorings) and
// ones made anew.

#include "SimulationFixture.h"
#include "common/MakePhysicsSystem.h"
#include "common/StaticFloor.h"

#include <algorithm>
#include <cstdio>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;
namespace
{

struct PyramidRun
{
    std::unique_ptr<PhysicsSystem> mSystem;
    std::vector<BodyID> mBoxes;
};

/// A world without sleeping, with the wide solver on or off, and a static 80 m x 80 m floor at y = 0.
PyramidRun MakeWorldWithFloor(bool inWide, bool inReuseColorings = true)
{
    PhysicsSettings settings;
    settings.mAllowSleeping = false;
    settings.mSolver.mWideColoredIslands = inWide;
    settings.mSolver.mReuseColorings = inReuseColorings;
    PyramidRun run{MakePhysicsSystem(settings), {}};
    const BodyCreationSettings floor = test::StaticFloorSettings(40.0f);
    (void)run.mSystem->GetBodyInterface().CreateAndAddBody(floor, Activation::DontActivate);
    return run;
}

/// A pyramid of boxes, offset layer on layer, on a floor: one island large enough to be colored.
PyramidRun MakePyramid(bool inWide, bool inReuseColorings = true)
{
    PyramidRun run = MakeWorldWithFloor(inWide, inReuseColorings);
    BodyInterface& bodies = run.mSystem->GetBodyInterface();
    const ShapeRef box = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    constexpr int cLayers = 6;
    for (int layer = 0; layer < cLayers; ++layer)
        for (int i = 0; i < cLayers - layer; ++i)
            for (int k = 0; k < cLayers - layer; ++k)
            {
                BodyCreationSettings settings;
                settings.mShape = box;
                // Each layer sits on the gaps of the one below, slightly turned: contacts of 1 to 4 points
                settings.mPosition = Vec3(float(i) + 0.5f * float(layer), 0.5f + 1.05f * float(layer),
                                          float(k) + 0.5f * float(layer));
                settings.mRotation = Quat(Eigen::AngleAxisf(0.02f * float(i + k), Vec3::UnitY()));
                settings.mMotionType = MotionType::Dynamic;
                settings.mObjectLayer = Layers::cMoving;
                settings.mFriction = 0.6f;
                run.mBoxes.push_back(bodies.CreateAndAddBody(settings, Activation::Activate).Value());
            }
    return run;
}

void StepBoth(PyramidRun& ioScalar, PyramidRun& ioWide, jobs::JobSystem* inJobs, int inSteps)
{
    for (int step = 0; step < inSteps; ++step)
    {
        for (PyramidRun* run : {&ioScalar, &ioWide})
            ASSERT_TRUE(
                (inJobs ? run->mSystem->Update(1.0f / 60.0f, 1, *inJobs) : run->mSystem->Update(1.0f / 60.0f))
                    .IsOk());
        BodyInterface& scalar = ioScalar.mSystem->GetBodyInterface();
        BodyInterface& wide = ioWide.mSystem->GetBodyInterface();
        for (size_t i = 0; i < ioScalar.mBoxes.size(); ++i)
        {
            // == rather than a bit compare: an impulse of zero may turn a -0 velocity into +0
            const bool same = scalar.GetPosition(ioScalar.mBoxes[i]).Value() ==
                                  wide.GetPosition(ioWide.mBoxes[i]).Value() &&
                              scalar.GetLinearVelocity(ioScalar.mBoxes[i]).Value() ==
                                  wide.GetLinearVelocity(ioWide.mBoxes[i]).Value() &&
                              scalar.GetAngularVelocity(ioScalar.mBoxes[i]).Value() ==
                                  wide.GetAngularVelocity(ioWide.mBoxes[i]).Value();
            ASSERT_TRUE(same) << "box " << i << " differs after step " << step << ": "
                              << scalar.GetPosition(ioScalar.mBoxes[i]).Value().transpose() << " vs "
                              << wide.GetPosition(ioWide.mBoxes[i]).Value().transpose();
        }
    }
}

TEST(WideSolverTest, SameStatesAsTheScalarSolver)
{
    PyramidRun scalar = MakePyramid(false), wide = MakePyramid(true);
    StepBoth(scalar, wide, nullptr, 200);
    // The pyramid was one colored island (it is the case the wide solver is for), and it still stands
    const StepStatistics& stats = wide.mSystem->GetLastStepStatistics();
    EXPECT_EQ(stats.mNumIslands, 1u);
    EXPECT_GE(stats.mNumManifolds, 128u);
    EXPECT_NEAR(wide.mSystem->GetBodyInterface().GetPosition(wide.mBoxes.back()).Value().y(), 5.5f, 0.05f);
}

TEST(WideSolverTest, SameStatesAsTheScalarSolverOnTwoThreads)
{
    jobs::JobSystem::Settings settings;
    settings.mNumThreads = 2;
    jobs::JobSystem jobSystem(settings);
    PyramidRun scalar = MakePyramid(false), wide = MakePyramid(true);
    StepBoth(scalar, wide, &jobSystem, 100);
}

TEST(WideSolverTest, AColoringTakenOverGivesTheSameStatesAsANewOne)
{
    jobs::JobSystem::Settings settings;
    settings.mNumThreads = 2;
    jobs::JobSystem jobSystem(settings);
    PyramidRun fresh = MakePyramid(true, false), reused = MakePyramid(true, true);
    StepBoth(fresh, reused, &jobSystem, 150);
    StepBoth(fresh, reused, nullptr, 50);
    // Once settled, the pyramid's contacts are the same from step to step: its coloring and its solve order
    // are taken over
    uint32_t colored = 0, takenOver = 0, ordersTakenOver = 0;
    for (int step = 0; step < 20; ++step)
    {
        for (PyramidRun* run : {&fresh, &reused})
            ASSERT_TRUE(run->mSystem->Update(1.0f / 60.0f).IsOk());
        colored += reused.mSystem->GetLastStepStatistics().mNumColoredIslands;
        takenOver += reused.mSystem->GetLastStepStatistics().mNumColoringsReused;
        ordersTakenOver += reused.mSystem->GetLastStepStatistics().mNumSolveOrdersReused;
        EXPECT_EQ(fresh.mSystem->GetLastStepStatistics().mNumColoringsReused, 0u);
        EXPECT_EQ(fresh.mSystem->GetLastStepStatistics().mNumSolveOrdersReused, 0u);
    }
    EXPECT_EQ(colored, 20u);
    EXPECT_GE(takenOver, 15u);
    EXPECT_GE(ordersTakenOver, 15u);
    StepBoth(fresh, reused, nullptr, 1); // Still the same states after those steps
}

TEST(WideSolverTest, ColoringsOfAPileFallingOverEachOtherAreTakenOverOnlyWhenTheSame)
{
    // Boxes dropped onto each other, turned: the pile's contacts change from step to step while their number
    // often stays the same, so a coloring taken over on its size alone would solve other constraints together
    auto makePile = [](bool inReuse)
    {
        PyramidRun run = MakeWorldWithFloor(true, inReuse);
        BodyInterface& bodies = run.mSystem->GetBodyInterface();
        const ShapeRef box = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
        for (int i = 0; i < 150; ++i)
        {
            BodyCreationSettings settings;
            settings.mShape = box;
            settings.mPosition =
                Vec3(float(i % 5) * 1.02f, 0.5f + 1.2f * float(i / 25), float((i / 5) % 5) * 1.02f);
            settings.mRotation =
                Quat(Eigen::AngleAxisf(0.4f * float(i % 7), Vec3(0.3f, 1.0f, 0.2f).normalized()));
            settings.mMotionType = MotionType::Dynamic;
            settings.mObjectLayer = Layers::cMoving;
            run.mBoxes.push_back(bodies.CreateAndAddBody(settings, Activation::Activate).Value());
        }
        return run;
    };
    PyramidRun fresh = makePile(false), reused = makePile(true);
    uint32_t colored = 0, takenOver = 0, ordersTakenOver = 0;
    for (int step = 0; step < 120; ++step)
    {
        StepBoth(fresh, reused, nullptr, 1);
        colored += reused.mSystem->GetLastStepStatistics().mNumColoredIslands;
        takenOver += reused.mSystem->GetLastStepStatistics().mNumColoringsReused;
        ordersTakenOver += reused.mSystem->GetLastStepStatistics().mNumSolveOrdersReused;
    }
    EXPECT_GT(colored, 60u) << "the pile must be colored for the test to mean anything";
    EXPECT_LT(ordersTakenOver, 120u) << "the pile's contacts must change for the test to mean anything";
    std::printf("[ figure   ] %u of %u colorings taken over, solve orders in %u of 120 steps\n", takenOver,
                colored, ordersTakenOver);
}

/// Small islands: single boxes, stacks of two and three, and tilted boxes on a floor (one to four
/// constraints each, so groups of four islands have rows of padding), some bouncy.
PyramidRun MakeSmallIslands(bool inWide)
{
    PyramidRun run = MakeWorldWithFloor(inWide);
    BodyInterface& bodies = run.mSystem->GetBodyInterface();
    const ShapeRef box = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    for (int i = 0; i < 23; ++i)
        for (int level = 0; level <= i % 3; ++level)
        {
            BodyCreationSettings settings;
            settings.mShape = box;
            settings.mPosition =
                Vec3(-30.0f + 2.5f * float(i), 0.6f + 1.1f * float(level), 0.1f * float(i % 5));
            settings.mRotation =
                Quat(Eigen::AngleAxisf(0.3f * float(i % 4), Vec3(0.2f, 1.0f, 0.1f).normalized()));
            settings.mMotionType = MotionType::Dynamic;
            settings.mObjectLayer = Layers::cMoving;
            settings.mFriction = 0.5f;
            settings.mRestitution = i % 4 == 0 ? 0.5f : 0.0f;
            run.mBoxes.push_back(bodies.CreateAndAddBody(settings, Activation::Activate).Value());
        }
    return run;
}

// Islands of up to four constraints are solved four at a time, one per lane of the wide solver: the same
// states as the scalar solver on each island alone
TEST(WideSolverTest, SmallIslandsInGroupsSameAsAlone)
{
    PyramidRun scalar = MakeSmallIslands(false), wide = MakeSmallIslands(true);
    StepBoth(scalar, wide, nullptr, 150);
    EXPECT_GE(wide.mSystem->GetLastStepStatistics().mNumIslands, 8u)
        << "the scene was meant to be many islands";
}

/// Drops a ball of the given restitution onto the settled pyramid's top box; returns its fastest upward speed
/// after it hit (the ball joins the pyramid's colored island).
float BounceOnPyramid(float inRestitution)
{
    PyramidRun run = MakePyramid(true);
    for (int step = 0; step < 60; ++step)
        EXPECT_TRUE(run.mSystem->Update(1.0f / 60.0f).IsOk());
    BodyInterface& bodies = run.mSystem->GetBodyInterface();
    BodyCreationSettings ball;
    ball.mShape = SphereShape::Create(0.5f).Value();
    ball.mPosition = bodies.GetPosition(run.mBoxes.back()).Value() + Vec3(0.0f, 3.5f, 0.0f);
    ball.mMotionType = MotionType::Dynamic;
    ball.mObjectLayer = Layers::cMoving;
    ball.mRestitution = inRestitution;
    const BodyID id = bodies.CreateAndAddBody(ball, Activation::Activate).Value();
    bool fell = false, joined = false;
    float fastestUp = 0.0f;
    for (int step = 0; step < 90; ++step)
    {
        EXPECT_TRUE(run.mSystem->Update(1.0f / 60.0f).IsOk());
        const float vy = bodies.GetLinearVelocity(id).Value().y();
        fell |= vy < -5.0f;
        if (fell) fastestUp = std::max(fastestUp, vy);
        const StepStatistics& stats = run.mSystem->GetLastStepStatistics();
        joined |= stats.mNumIslands == 1 && stats.mNumManifolds >= 128;
    }
    EXPECT_TRUE(fell) << "the ball did not fall";
    EXPECT_TRUE(joined) << "the ball never made one colored island with the pyramid";
    return fastestUp;
}

// The restitution pass of a colored island runs only where a constraint bounces (it costs a barrier per
// color): a bouncy ball landing on the pyramid must still bounce, a dead one must not
TEST(WideSolverTest, BallBouncesOnAColoredIsland)
{
    const float bouncy = BounceOnPyramid(0.9f);
    const float dead = BounceOnPyramid(0.0f);
    EXPECT_GT(bouncy, 3.0f) << "a ball of restitution 0.9 hit at about 7 m/s";
    EXPECT_LT(dead, 1.0f);
}

} // namespace
} // namespace cairn::test
