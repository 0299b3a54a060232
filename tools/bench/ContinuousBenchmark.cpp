// cairn-bench-continuous: what a MotionQuality::LinearCast body costs against a discrete one, in the same
// scene (issue 31's target: at most 3x a discrete body's narrow phase).
//  step_projectiles  the shared world's 20,020 static boxes on a floor; 256 balls (radius 0.35 m, as the demo
//  throws)
//                    shot down into it at 100-300 m/s from 10-30 m up, 240 steps of 1/60 s, one thread. The
//                    same balls (same seed) run once discrete and once linear-cast, alternating, per
//                    repetition.
// Prints per step the narrow phase (pairs included) and the linear casts in ms, the casts that stopped a
// ball, and the cost ratio (narrow phase + casts of the linear-cast run) / (narrow phase of the discrete
// run), with the balls' final mean height as a checksum (a ball below the static boxes' floor has tunnelled).

#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "common/BenchOptions.h"
#include "common/BenchScenes.h"
#include "common/FrameTimes.h"
#include "common/MachineInfo.h"
#include "common/PhysicsSystemOrExit.h"
#include "common/SharedBenchData.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace cairn;
using namespace cairn::physics;

namespace
{
constexpr int cBalls = 256;
constexpr int cSteps = 240;

struct RunResult
{
    double mNarrowMs = 0.0;     ///< Per step
    double mContinuousMs = 0.0; ///< Per step
    double mStepMs = 0.0;       ///< Per step
    uint64_t mMovedBack = 0;    ///< Casts that stopped a ball, over the run
    double mMeanHeight = 0.0;   ///< Of the balls at the end
    double mLowestHeight = 0.0;
    int mBelowFloor = 0; ///< Balls whose centre ended below the floor's top, over it: passed through it
};

RunResult Run(const SharedBenchData& inData, MotionQuality inQuality)
{
    const std::unique_ptr<PhysicsSystem> system =
        tools::CreatePhysicsSystemOrExit("cairn-bench-continuous", tools::BenchSettings(true));
    BodyInterface& bodies = system->GetBodyInterface();
    std::vector<BodyCreationSettings> statics;
    for (const BenchBox& box : inData.mStatic)
        statics.push_back(
            tools::BoxSettings(box.mCenter, box.mHalfExtent, box.mYaw, MotionType::Static, 0.5f));
    std::vector<BodyID> staticIDs;
    tools::AddBatch(bodies, statics, Activation::DontActivate, staticIDs);
    AABB world;
    for (const BenchBox& box : inData.mStatic)
        world.Encapsulate(AABB::FromCenterExtent(box.mCenter, box.mHalfExtent));

    // A floor under it all, so that balls falling between the boxes land and roll into them
    const Vec3 worldCenter = 0.5f * (world.mMin + world.mMax);
    const Vec3 worldHalf = world.HalfExtent();
    const Vec3 floorHalf(worldHalf.x() + 100.0f, 1.0f, worldHalf.z() + 100.0f);
    BodyCreationSettings floor =
        tools::BoxSettings(Vec3(worldCenter.x(), world.mMin.y() - 1.0f, worldCenter.z()), floorHalf, 0.0f,
                           MotionType::Static, 0.5f);
    (void)bodies.CreateAndAddBody(floor, Activation::DontActivate);

    std::mt19937 random(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const ShapeRef ball = SphereShape::Create(0.35f).Value();
    std::vector<BodyID> balls;
    for (int i = 0; i < cBalls; ++i)
    {
        BodyCreationSettings settings;
        settings.mShape = ball;
        const Vec3 at(world.mMin.x() + unit(random) * (world.mMax.x() - world.mMin.x()),
                      world.mMax.y() + 10.0f + 20.0f * unit(random),
                      world.mMin.z() + unit(random) * (world.mMax.z() - world.mMin.z()));
        settings.mPosition = at;
        const Vec3 direction = Vec3(unit(random) - 0.5f, -1.0f, unit(random) - 0.5f).normalized();
        settings.mLinearVelocity = (100.0f + 200.0f * unit(random)) * direction;
        settings.mMotionType = MotionType::Dynamic;
        settings.mObjectLayer = Layers::cMoving;
        settings.mDensity = 3000.0f;
        settings.mMotionQuality = inQuality;
        balls.push_back(bodies.CreateAndAddBody(settings, Activation::Activate).Value());
    }
    RunResult result;
    for (int step = 0; step < cSteps; ++step)
    {
        (void)system->Update(1.0f / 60.0f);
        const StepStatistics& stats = system->GetLastStepStatistics();
        result.mNarrowMs += stats.mNarrowPhaseMs;
        result.mContinuousMs += stats.mContinuousMs;
        result.mStepMs += stats.mTotalMs;
        result.mMovedBack += stats.mNumLinearCastsMovedBack;
    }
    result.mNarrowMs /= cSteps;
    result.mContinuousMs /= cSteps;
    result.mStepMs /= cSteps;
    result.mLowestHeight = 1.0e30;
    for (const BodyID& id : balls)
    {
        const double y = bodies.GetPosition(id).Value().y();
        result.mMeanHeight += y / cBalls;
        result.mLowestHeight = std::min(result.mLowestHeight, y);
        // Under the floor's top and over the floor (some roll off its edges and fall past it)
        const Vec3 at = bodies.GetPosition(id).Value();
        const bool overFloor = std::abs(at.x() - worldCenter.x()) < floorHalf.x() &&
                               std::abs(at.z() - worldCenter.z()) < floorHalf.z();
        result.mBelowFloor += y < world.mMin.y() && overFloor ? 1 : 0;
    }
    return result;
}

void Print(const char* inQuality, int inRepetition, const RunResult& inRun)
{
    std::printf(
        "step_projectiles %s rep %d: step %.3f ms  narrow(+pairs) %.3f ms  casts %.3f ms  | casts that "
        "stopped a ball %llu  | ball heights mean %.3f lowest %.3f m, %d below the floor\n",
        inQuality, inRepetition, inRun.mStepMs, inRun.mNarrowMs, inRun.mContinuousMs,
        static_cast<unsigned long long>(inRun.mMovedBack), inRun.mMeanHeight, inRun.mLowestHeight,
        inRun.mBelowFloor);
}
} // namespace

int main(int inArgc, char** inArgv)
{
    tools::BenchOptions options;
    if (auto stop = tools::ParseBenchOptions(
            inArgc, inArgv, "cairn-bench-continuous: linear-cast bodies against discrete ones",
            {"step_projectiles"}, options))
        return *stop;
#ifdef NDEBUG
    const char* buildType = "Release";
#else
    const char* buildType = "Debug (figures not representative)";
#endif
    std::printf("cairn-bench-continuous: build %s, %d repetitions; %s\n", buildType, options.mRepetitions,
                tools::DescribeMachine().c_str());
    Result<SharedBenchData> data = LoadSharedBenchData();
    if (!data)
    {
        std::printf("step_projectiles skipped: %s\n", data.GetError().mMessage.c_str());
        return 0;
    }
    std::vector<double> ratios, discreteNarrow, castNarrow, casts;
    for (int i = 0; i < options.mRepetitions; ++i)
    {
        const RunResult discrete = Run(data.Value(), MotionQuality::Discrete);
        Print("discrete", i, discrete);
        const RunResult cast = Run(data.Value(), MotionQuality::LinearCast);
        Print("linear-cast", i, cast);
        discreteNarrow.push_back(discrete.mNarrowMs);
        castNarrow.push_back(cast.mNarrowMs);
        casts.push_back(cast.mContinuousMs);
        ratios.push_back((cast.mNarrowMs + cast.mContinuousMs) / discrete.mNarrowMs);
    }
    std::printf("step_projectiles median of %d: narrow(+pairs) discrete %.3f ms, linear-cast %.3f ms + casts "
                "%.3f ms: a linear-cast ball costs %.2fx a discrete one's narrow phase\n",
                options.mRepetitions, tools::Median(discreteNarrow), tools::Median(castNarrow),
                tools::Median(casts), tools::Median(ratios));
    return 0;
}
