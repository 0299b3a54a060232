// step_pile2k as a test: the shared workload's 2,000 boxes fall onto its 20,020 static boxes for 10 s, then
// every box still on the world must be asleep, and no box sunk into another body by more than the solver's
// slop and 5 mm (a few slide off the world's edge and fall for ever: they are counted apart). Boxes land
// there at up to 15 m/s, tilted, turned and over edges: a box-box manifold of a single corner point once let
// a landing box spin 21 cm into the box under it and stay there, awake.

#include "SimulationFixture.h"
#include "common/ShapeExpect.h"
#include "common/SharedBenchData.h"
#include "common/WorkloadBodies.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;
namespace
{

using PileSettlingTest = SimulationFixture;

TEST_F(PileSettlingTest, TheSharedPileComesToRestWithNoBoxSunkIntoAnother)
{
    if (!std::filesystem::exists(GetSharedBenchDir()))
        GTEST_SKIP() << "shared workload not found at " << GetSharedBenchDir();
    const Result<SharedBenchData> data = LoadSharedBenchData();
    ASSERT_TRUE(data) << data.GetError().mMessage;
    PhysicsSettings settings;
    settings.mMaxBodies = 32768;
    settings.mSolver.mVelocityIterations = 10; // step_pile2k's
    settings.mSolver.mPositionIterations = 2;
    ResetWorld(settings);
    ASSERT_EQ(AddWorkloadBoxes(Bodies(), data.Value().mStatic, MotionType::Static).size(),
              data.Value().mStatic.size());
    const std::vector<BodyID> boxes = AddWorkloadBoxes(Bodies(), data.Value().mDynamic, MotionType::Dynamic);
    ASSERT_EQ(boxes.size(), data.Value().mDynamic.size());
    Step(600);

    // Each box's deepest overlap with any other body, at its pose now
    float worldBottom = cLargeFloat;
    for (const BenchBox& box : data.Value().mStatic)
        worldBottom = std::min(worldBottom, box.mCenter.y() - box.mHalfExtent.y());
    const float slop = System().GetSettings().mSolver.mPenetrationSlop;
    float deepest = 0.0f, sum = 0.0f;
    int awake = 0, fellOff = 0, overSlop = 0;
    std::vector<ShapeQueryHit> hits;
    for (size_t i = 0; i < boxes.size(); ++i)
    {
        const BodyID& box = boxes[i];
        if (Position(box).y() < worldBottom)
        {
            ++fellOff;
            continue;
        }
        awake += IsActive(box) ? 1 : 0;
        QueryFilter filter;
        filter.mIgnoreBody = box;
        const Transform pose{Position(box), Bodies().GetRotation(box).Value()};
        const BoxShape shape(data.Value().mDynamic[i].mHalfExtent);
        ASSERT_TRUE(System().GetWorldQuery().CollideShape(shape, pose, hits, filter, 0.0f));
        float depth = 0.0f;
        for (const ShapeQueryHit& hit : hits)
            depth = std::max(depth, MaxPenetration(hit.mManifold));
        deepest = std::max(deepest, depth);
        sum += depth;
        overSlop += depth > slop + 0.001f ? 1 : 0;
    }
    const int onTheWorld = int(boxes.size()) - fellOff;
    std::printf(
        "[ figure   ] after 10 s: %d boxes fell off the world; of the %d on it, %d awake; overlap mean "
        "%.2f mm, deepest %.1f mm; %d boxes deeper than the slop and 1 mm\n",
        fellOff, onTheWorld, awake, 1000.0f * sum / float(onTheWorld), 1000.0f * deepest, overSlop);
    EXPECT_EQ(awake, 0);
    EXPECT_LT(fellOff, int(boxes.size()) / 100) << "the pile must land on the world, not beside it";
    EXPECT_LE(deepest, slop + 0.005f);
}

} // namespace
} // namespace cairn::test
