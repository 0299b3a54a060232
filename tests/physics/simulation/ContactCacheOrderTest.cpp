// The contact cache that each step warm-starts from must be in key order with every body pair finding its
// manifolds. The narrow phase's merge checks the order as it copies (and then skips the sort): these scenes
// break the order on purpose, so a merge that took them for sorted would leave a cache the next step cannot
// search.

#include "SimulationFixture.h"
#include "cairn/physics/shapes/CompoundShape.h"

namespace cairn::test
{
using namespace cairn::physics;
namespace
{

class ContactCacheOrderTest : public SimulationFixture
{
protected:
    void StepAndCheck(int inSteps)
    {
        for (int i = 0; i < inSteps; ++i)
        {
            ASSERT_TRUE(UpdateWorld(cDeltaTime).IsOk());
            ASSERT_TRUE(System().IsContactCacheConsistent()) << "after step " << i;
        }
    }
};

TEST_F(ContactCacheOrderTest, SleepingBodiesWokenInsideTheStep)
{
    // A row of boxes falls asleep; boxes created later (higher body indices) fall onto them. The sleeping
    // boxes are woken by those contacts in the middle of the narrow phase and collided in a second round,
    // whose pairs (low indices) come after the first round's in the cache
    AddFloor();
    std::vector<BodyID> resting;
    for (int i = 0; i < 8; ++i)
        resting.push_back(
            AddDynamic(DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(float(i) * 1.5f, 0.5f, 0))));
    StepAndCheck(90);
    for (const BodyID& id : resting)
        ASSERT_FALSE(IsActive(id)) << "the row should be asleep before the others land";
    for (int i = 0; i < 8; ++i)
        AddDynamic(DynamicSettings(Box(Vec3(0.4f, 0.4f, 0.4f)), Vec3(float(i) * 1.5f, 1.5f, 0.1f)));
    StepAndCheck(60);
    EXPECT_TRUE(IsActive(resting.front()) || Position(resting.front()).y() < 0.6f);
}

TEST_F(ContactCacheOrderTest, CompoundsWithSeveralManifoldsPerPair)
{
    // Each compound touches the floor with several parts: one body pair, several manifolds, in the order the
    // parts were collided (sleeping off, so that they stay in the step; merging off, else the parts'
    // manifolds on the one floor become one)
    PhysicsSettings settings;
    settings.mAllowSleeping = false;
    settings.mMergeManifolds = false;
    ResetWorld(settings);
    AddFloor();
    std::vector<CompoundShape::SubShape> parts;
    for (int part = 3; part >= 0; --part)
        parts.push_back({Box(Vec3(0.4f, 0.4f, 0.4f)),
                         Transform{Vec3(float(part) - 1.5f, 0, float(part % 2)), Quat::Identity()}});
    const ShapeRef shape = CompoundShape::Create(parts).Value();
    for (int i = 0; i < 4; ++i)
        AddDynamic(DynamicSettings(shape, Vec3(float(i) * 5.0f, 0.5f, 0)));
    StepAndCheck(60);
    EXPECT_GE(System().GetLastStepStatistics().mNumManifolds, 16u);
}

} // namespace
} // namespace cairn::test
