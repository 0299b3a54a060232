// PhysicsSettings::mMergeManifolds in the step: a box resting on eight triangles of a flat height field is
// one manifold of four points with merging (the default), several without, and rests the same either way.

#include "SimulationFixture.h"
#include "cairn/physics/shapes/HeightFieldShape.h"

#include <vector>

namespace cairn::test
{
using namespace cairn::physics;
namespace
{

class ManifoldMergingTest : public SimulationFixture
{
protected:
    struct Outcome
    {
        uint32_t mManifolds;
        uint32_t mPoints;
        float mHeight;
    };
    /// A 1.4 m box dropped onto the corner where four cells of a flat height field meet; after 2 s.
    Outcome BoxOnFourCells(bool inMerge)
    {
        PhysicsSettings settings;
        settings.mMergeManifolds = inMerge;
        settings.mAllowSleeping = false; // Keep it in the step, so that its manifolds are counted
        ResetWorld(settings);
        const std::vector<float> heights(9 * 9, 0.0f);
        AddStatic(HeightFieldShape::Create(9, 9, 1.0f, heights).Value(), Vec3(-4.0f, 0.0f, -4.0f));
        const BodyID box = AddDynamic(DynamicSettings(Box(Vec3(0.7f, 0.7f, 0.7f)), Vec3(0.0f, 0.75f, 0.0f)));
        Step(120);
        const StepStatistics& stats = System().GetLastStepStatistics();
        return {stats.mNumManifolds, stats.mNumContactPoints, Position(box).y()};
    }
};

TEST_F(ManifoldMergingTest, ABoxOnEightTrianglesIsOneManifoldOfFourPoints)
{
    const Outcome merged = BoxOnFourCells(true);
    EXPECT_EQ(merged.mManifolds, 1u);
    EXPECT_EQ(merged.mPoints, 4u);
    EXPECT_NEAR(merged.mHeight, 0.7f, 0.01f);
}

TEST_F(ManifoldMergingTest, WithoutMergingEveryTriangleHasItsManifoldAndTheBoxRestsAlike)
{
    const Outcome separate = BoxOnFourCells(false);
    EXPECT_GE(separate.mManifolds, 4u);
    EXPECT_GT(separate.mPoints, 4u);
    EXPECT_NEAR(separate.mHeight, 0.7f, 0.01f);
}

} // namespace
} // namespace cairn::test
