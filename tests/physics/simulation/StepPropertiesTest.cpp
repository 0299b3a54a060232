#include "SimulationFixture.h"
#include "common/AllocationCounter.h"
#include "common/MakePhysicsSystem.h"
#include "common/StaticFloor.h"

namespace cairn::test
{
using namespace cairn::physics;

TEST(BodyLayout, BodyFitsIn256Bytes)
{
    EXPECT_LE(sizeof(Body), 256u);
}

using StepPropertiesTest = SimulationFixture;

TEST_F(StepPropertiesTest, WarmSceneStepsWithoutHeapAllocation)
{
    AddFloor();
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j)
            AddDynamic(DynamicSettings(Box(Vec3(0.4f, 0.4f, 0.4f)),
                                       Vec3(float(i), 0.5f + 1.2f * float(j), 0.3f * float(i))));
    Step(120); // warm: contact arrays reach their size
    AllocationScope scope;
    Step(60);
    EXPECT_EQ(scope.GetCount(), 0u);
}

TEST_F(StepPropertiesTest, BatchAddMakesBodiesSimulated)
{
    AddFloor();
    std::vector<BodyID> ids;
    for (int i = 0; i < 20; ++i)
        ids.push_back(Bodies().CreateBody(DynamicSettings(Sphere(0.2f), Vec3(float(i), 2, 0))).Value());
    Result<BodyInterface::AddBatch> batch = Bodies().AddBodiesPrepare(ids);
    ASSERT_TRUE(batch.IsOk());
    EXPECT_FALSE(Bodies().IsAdded(ids[0]).Value()) << "not visible before finalize";
    EXPECT_EQ(Bodies().AddBody(ids[3], Activation::Activate).GetError().mCode, ErrorCode::AlreadyAdded)
        << "a pending body cannot be added twice";
    ASSERT_TRUE(Bodies().AddBodiesFinalize(batch.Value(), Activation::Activate).IsOk());
    Step(60);
    for (const BodyID& id : ids)
        EXPECT_NEAR(Position(id).y(), 0.2f, 0.01f);
}

TEST_F(StepPropertiesTest, StatisticsGiveEachPhaseItsSerialPart)
{
    AddFloor();
    for (int i = 0; i < 10; ++i)
        for (int j = 0; j < 10; ++j)
            AddDynamic(DynamicSettings(Box(Vec3(0.4f, 0.4f, 0.4f)),
                                       Vec3(float(i), 0.5f + 0.1f * float(j), float(j))));
    Step(30);
    const StepStatistics stats = System().GetLastStepStatistics();
    EXPECT_GT(stats.mSerialMs, 0.0);
    EXPECT_LT(stats.mSerialMs, stats.mTotalMs) << "the step's loops were not counted as parallel";
    EXPECT_LE(stats.mNarrowPhaseSerialMs, stats.mNarrowPhaseMs);
    EXPECT_LE(stats.mIslandsSerialMs, stats.mIslandsMs);
    EXPECT_LE(stats.mSolveSerialMs, stats.mSolveMs);
    EXPECT_LT(stats.mSolveSerialMs, stats.mSolveMs) << "the solve's loops were not counted as parallel";
    EXPECT_LE(stats.mFinishSerialMs, stats.mFinishMs);
    EXPECT_LE(stats.mNarrowPhaseSerialMs + stats.mIslandsSerialMs + stats.mSolveSerialMs +
                  stats.mFinishSerialMs,
              stats.mSerialMs + 1e-6);
}

TEST_F(StepPropertiesTest, SameSceneGivesBitIdenticalResults)
{
    auto run = [](std::vector<Vec3>& outPositions)
    {
        const std::unique_ptr<PhysicsSystem> system = MakePhysicsSystem();
        BodyInterface& bodies = system->GetBodyInterface();
        const BodyCreationSettings floor = test::StaticFloorSettings(20.0f);
        (void)bodies.CreateAndAddBody(floor, Activation::DontActivate);
        std::vector<BodyID> ids;
        for (int i = 0; i < 30; ++i)
        {
            BodyCreationSettings box;
            box.mShape = BoxShape::Create(Vec3(0.3f, 0.3f, 0.3f)).Value();
            box.mPosition = Vec3(0.1f * float(i % 5), 0.5f + 0.7f * float(i), 0.05f * float(i % 3));
            box.mRotation = Quat(Eigen::AngleAxisf(0.1f * float(i), Vec3(1, 1, 0).normalized()));
            ids.push_back(bodies.CreateAndAddBody(box, Activation::Activate).Value());
        }
        for (int step = 0; step < 300; ++step)
            (void)UpdateWorld(*system, 1.0f / 60.0f);
        for (const BodyID& id : ids)
            outPositions.push_back(bodies.GetPosition(id).Value());
    };
    std::vector<Vec3> first, second;
    run(first);
    run(second);
    ASSERT_EQ(first.size(), second.size());
    for (size_t i = 0; i < first.size(); ++i)
        EXPECT_EQ(first[i], second[i]) << "body " << i;
}

} // namespace cairn::test
