// cairn-bench-step: the physics step benchmarks of ../shared/bench/SPEC.md.
//  step_pile2k   2,000 dynamic boxes fall onto the 20,020 static boxes: 600 steps of 1/60 s.
//  step_pyramid  a 3D pyramid of 1,240 boxes on a static floor: 500 steps, sleeping disabled.
//  step_ragdolls 160 humanoid ragdolls of 23 parts (3,680 bodies, 3,520 swing-twist joints) in 16 piles of
//  10,
//                dropped onto a rolling height field: 500 steps (issue 33's scene, after Jolt's
//                PerformanceTest "Ragdoll": its piles and steps, this engine's humanoid and ground).
// Prints ms per step (mean, p99, max) for each repetition and the median over repetitions, the mean time per
// phase and of its serial part (the updating thread outside parallel loops: StepStatistics::mSerialMs), and a
// checksum (sum of final body heights and contact points) that proves the work was done; for each thread
// count of --threads (default 1,2: a job system of that many threads), then the speed-up. The checksum must
// not change with the thread count (the step is deterministic across thread counts), and how the job system
// handed out the work (loop parts workers joined, queued jobs, and workers that ran out of work and slept,
// per step). --update-beside-from sets the active bodies a helper thread from which the broad-phase update
// runs beside the step. --queued-loops turns the job system's loop board off
// (JobSystem::Settings::mUseLoopBoard), to measure what it saves.

#include "broadphase/BroadPhaseQuadTree.h"
#include "cairn/jobs/JobSystem.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/ragdoll/HumanoidRagdoll.h"
#include "cairn/physics/shapes/HeightFieldShape.h"
#include "common/BenchOptions.h"
#include "common/BenchScenes.h"
#include "common/CoreToCoreLatency.h"
#include "common/FrameTimes.h"
#include "common/MachineInfo.h"
#include "common/PhysicsSystemOrExit.h"
#include "common/SharedBenchData.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace cairn;
using namespace cairn::physics;
using tools::AddBatch;
using tools::BenchSettings;
using tools::BoxSettings;

namespace
{
struct RunResult
{
    tools::TimingSummary mStep;
    StepStatistics mPhaseSums;                           ///< Phase times summed over all steps
    double mHeightChecksum = 0.0;                        ///< Sum of final y of the dynamic bodies
    uint64_t mContactPoints = 0;                         ///< Contact points summed over all steps
    uint64_t mManifolds = 0;                             ///< Contact manifolds summed over all steps
    uint64_t mBodyPairs = 0;                             ///< Broad-phase pairs summed over all steps
    uint64_t mReusedBodyPairs = 0;                       ///< ... of which took last step's manifolds over
    BroadPhaseQuadTree::CandidateCacheStats mCandidates; ///< How the pair search served static candidates
    uint64_t mColoredIslands = 0;                        ///< Islands colored, summed over all steps
    uint64_t mReusedColorings = 0;                       ///< ... of which took the previous step's coloring
    uint64_t mReusedSolveOrders = 0;                     ///< Steps that took the previous step's solve order
    /// How the job system handed out the run's work: loop parts that workers took from the loop board, jobs
    /// run through the queue (loops that found the board taken or off, the broad-phase update), and the times
    /// a worker ran out of work and slept. Few parts taken on many threads means the caller ran most loops
    /// alone
    uint64_t mLoopPartsJoined = 0;
    uint64_t mJobsRun = 0;
    uint64_t mWorkerSleeps = 0;
    int mSteps = 0;
};

/// The broad phase's margin for cached static candidates (--candidate-margin); the engine's default unless
/// given.
float gCandidateMargin = PhysicsSettings().mBroadPhaseCandidateMargin;
bool gQueuedLoops = false;
/// PhysicsSettings::mUpdateBesideStepMinActiveBodies (--update-beside-from); the engine's default unless
/// given.
uint32_t gUpdateBesideFrom = PhysicsSettings().mUpdateBesideStepMinActiveBodies;
/// PhysicsSettings::mMinChunksPerThread (--min-chunks-per-thread); the engine's default unless given.
uint32_t gMinChunksPerThread = PhysicsSettings().mMinChunksPerThread;

/// The scenes' settings with the options above.
PhysicsSettings StepSettings(bool inAllowSleeping)
{
    PhysicsSettings settings = BenchSettings(inAllowSleeping, gCandidateMargin);
    settings.mUpdateBesideStepMinActiveBodies = gUpdateBesideFrom;
    settings.mMinChunksPerThread = gMinChunksPerThread;
    return settings;
}

/// The job system a run steps with: inThreads threads, the loop board as --queued-loops says.
jobs::JobSystem::Settings JobSettings(uint32_t inThreads)
{
    jobs::JobSystem::Settings settings;
    settings.mNumThreads = inThreads;
    settings.mUseLoopBoard = !gQueuedLoops;
    return settings;
}

RunResult RunScene(PhysicsSystem& ioSystem, const std::vector<BodyID>& inDynamic, int inSteps,
                   jobs::JobSystem& ioJobs)
{
    RunResult result;
    result.mSteps = inSteps;
    std::vector<double> stepMs;
    stepMs.reserve(size_t(inSteps));
    const jobs::JobSystem::Stats jobsBefore = ioJobs.GetStats();
    for (int step = 0; step < inSteps; ++step)
    {
        const auto start = std::chrono::steady_clock::now();
        (void)ioSystem.Update(1.0f / 60.0f, 1, ioJobs);
        stepMs.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        const StepStatistics& stats = ioSystem.GetLastStepStatistics();
        result.mPhaseSums.mBroadPhaseUpdateMs += stats.mBroadPhaseUpdateMs;
        result.mPhaseSums.mNarrowPhaseMs += stats.mNarrowPhaseMs;
        result.mPhaseSums.mIslandsMs += stats.mIslandsMs;
        result.mPhaseSums.mSolveMs += stats.mSolveMs;
        result.mPhaseSums.mFinishMs += stats.mFinishMs;
        result.mPhaseSums.mTotalMs += stats.mTotalMs;
        result.mPhaseSums.mNarrowPhaseSerialMs += stats.mNarrowPhaseSerialMs;
        result.mPhaseSums.mIslandsSerialMs += stats.mIslandsSerialMs;
        result.mPhaseSums.mSolveSerialMs += stats.mSolveSerialMs;
        result.mPhaseSums.mFinishSerialMs += stats.mFinishSerialMs;
        result.mPhaseSums.mSerialMs += stats.mSerialMs;
        result.mContactPoints += stats.mNumContactPoints;
        result.mManifolds += stats.mNumManifolds;
        result.mBodyPairs += stats.mNumBodyPairs;
        result.mReusedBodyPairs += stats.mNumReusedBodyPairs;
        result.mColoredIslands += stats.mNumColoredIslands;
        result.mReusedColorings += stats.mNumColoringsReused;
        result.mReusedSolveOrders += stats.mNumSolveOrdersReused;
    }
    result.mStep = tools::Summarize(stepMs);
    const jobs::JobSystem::Stats jobsAfter = ioJobs.GetStats();
    result.mLoopPartsJoined = jobsAfter.mLoopPartsJoined - jobsBefore.mLoopPartsJoined;
    result.mJobsRun = jobsAfter.mJobsRun - jobsBefore.mJobsRun;
    result.mWorkerSleeps = jobsAfter.mWorkerSleeps - jobsBefore.mWorkerSleeps;
    for (const BodyID& id : inDynamic)
        result.mHeightChecksum += ioSystem.GetBodyInterface().GetPosition(id).Value().y();
    if (const auto* quadTree = dynamic_cast<const BroadPhaseQuadTree*>(&ioSystem.GetBroadPhase()))
        result.mCandidates = quadTree->GetCandidateCacheStats();
    return result;
}

RunResult RunPile2k(const SharedBenchData& inData, jobs::JobSystem& ioJobs)
{
    const std::unique_ptr<PhysicsSystem> system =
        tools::CreatePhysicsSystemOrExit("cairn-bench-step", StepSettings(true));
    std::vector<BodyCreationSettings> statics, dynamics;
    for (const BenchBox& box : inData.mStatic)
        statics.push_back(BoxSettings(box.mCenter, box.mHalfExtent, box.mYaw, MotionType::Static, 0.5f));
    for (const BenchBox& box : inData.mDynamic)
        dynamics.push_back(BoxSettings(box.mCenter, box.mHalfExtent, box.mYaw, MotionType::Dynamic, 0.5f));
    std::vector<BodyID> staticIDs, dynamicIDs;
    AddBatch(system->GetBodyInterface(), statics, Activation::DontActivate, staticIDs);
    AddBatch(system->GetBodyInterface(), dynamics, Activation::Activate, dynamicIDs);
    return RunScene(*system, dynamicIDs, 600, ioJobs);
}

RunResult RunPyramid(jobs::JobSystem& ioJobs)
{
    const std::unique_ptr<PhysicsSystem> system =
        tools::CreatePhysicsSystemOrExit("cairn-bench-step", StepSettings(tools::cPyramidAllowSleeping));
    const tools::PyramidScene scene = tools::AddPyramid(system->GetBodyInterface());
    return RunScene(*system, scene.mBoxes, 500, ioJobs);
}

RunResult RunRagdolls(jobs::JobSystem& ioJobs)
{
    const std::unique_ptr<PhysicsSystem> system =
        tools::CreatePhysicsSystemOrExit("cairn-bench-step", StepSettings(true));
    // The ground: 64 x 64 cells of 1 m round the origin, waves 0.3 m high
    const uint32_t samples = 65;
    std::vector<float> heights(samples * samples);
    for (uint32_t z = 0; z < samples; ++z)
        for (uint32_t x = 0; x < samples; ++x)
            heights[x + z * samples] = 0.15f * std::sin(0.5f * float(x)) * std::cos(0.4f * float(z));
    BodyCreationSettings ground;
    ground.mShape = HeightFieldShape::Create(samples, samples, 1.0f, heights).Value();
    ground.mPosition = Vec3(-32.0f, 0.0f, -32.0f);
    ground.mMotionType = MotionType::Static;
    ground.mObjectLayer = Layers::cStatic;
    ground.mFriction = 0.6f;
    (void)system->GetBodyInterface().CreateAndAddBody(ground, Activation::DontActivate);
    // 4 x 4 piles 4 m apart, 10 ragdolls each lying on its back 0.6 m above the last, each turned a tenth of
    // a turn more about the vertical (Jolt's RagdollScene(4, 10, 0.6))
    const RagdollSettings humanoid = MakeHumanoidRagdoll();
    std::vector<BodyID> bodies;
    uint32_t group = 1;
    for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 4; ++col)
            for (int i = 0; i < 10; ++i)
            {
                const Vec3 pile(4.0f * (float(col) - 1.5f), 0.0f, 4.0f * (float(row) - 1.5f));
                const Quat rotation =
                    Quat(Eigen::AngleAxisf(2.0f * 3.14159265f * float(i) / 10.0f, Vec3::UnitY())) *
                    Quat(Eigen::AngleAxisf(-0.5f * 3.14159265f, Vec3::UnitX())); // On its back
                // Its pelvis (about 1 m up the standing figure) at the pile's place, 0.6 m a ragdoll up
                const Vec3 position =
                    pile + Vec3(0.0f, 0.6f * float(i + 1), 0.0f) - rotation * Vec3(0.0f, 0.97f, 0.0f);
                Result<Ragdoll> ragdoll =
                    Ragdoll::Create(*system, humanoid, position, rotation, group++, Activation::Activate);
                if (!ragdoll)
                {
                    std::fprintf(stderr, "cairn-bench-step: a ragdoll: %s\n",
                                 ragdoll.GetError().mMessage.c_str());
                    std::exit(1);
                }
                bodies.insert(bodies.end(), ragdoll.Value().GetBodies().begin(),
                              ragdoll.Value().GetBodies().end());
            }
    return RunScene(*system, bodies, 500, ioJobs);
}

/// Prints the repetitions and returns the median of the mean step times.
double Print(const char* inName, uint32_t inThreads, const std::vector<RunResult>& inRuns)
{
    std::vector<double> means, p99s, maxes;
    for (size_t i = 0; i < inRuns.size(); ++i)
    {
        const RunResult& run = inRuns[i];
        const uint64_t candidateQueries =
            std::max<uint64_t>(run.mCandidates.mReused + run.mCandidates.mWalked + run.mCandidates.mRefilled +
                                   run.mCandidates.mUncached,
                               1);
        std::printf(
            "%s threads=%u rep %zu: mean %.3f ms  p99 %.3f ms  max %.3f ms  | per step: "
            "broadphase-update %.3f  "
            "narrow(+pairs) %.3f  islands %.3f  solve %.3f  finish %.3f ms  | serial %.3f ms (%.1f%%): "
            "narrow %.3f  islands %.3f  solve %.3f  finish %.3f ms  | checksum heights %.3f "
            "contacts %llu  | manifolds %llu  body pairs %llu  | pairs reused %.1f%%  "
            "| static candidates reused %.1f%% (%.1f%% walked, too many)  "
            "| colorings reused %llu of %llu  | solve orders reused in %llu of %d steps  "
            "| per step: loop parts joined %.1f, queued jobs %.1f, worker sleeps %.2f\n",
            inName, inThreads, i, run.mStep.mMean, run.mStep.mP99, run.mStep.mMax,
            run.mPhaseSums.mBroadPhaseUpdateMs / run.mSteps, run.mPhaseSums.mNarrowPhaseMs / run.mSteps,
            run.mPhaseSums.mIslandsMs / run.mSteps, run.mPhaseSums.mSolveMs / run.mSteps,
            run.mPhaseSums.mFinishMs / run.mSteps, run.mPhaseSums.mSerialMs / run.mSteps,
            100.0 * run.mPhaseSums.mSerialMs / std::max(run.mPhaseSums.mTotalMs, 1e-9),
            run.mPhaseSums.mNarrowPhaseSerialMs / run.mSteps, run.mPhaseSums.mIslandsSerialMs / run.mSteps,
            run.mPhaseSums.mSolveSerialMs / run.mSteps, run.mPhaseSums.mFinishSerialMs / run.mSteps,
            run.mHeightChecksum, static_cast<unsigned long long>(run.mContactPoints),
            static_cast<unsigned long long>(run.mManifolds), static_cast<unsigned long long>(run.mBodyPairs),
            100.0 * double(run.mReusedBodyPairs) / double(std::max<uint64_t>(run.mBodyPairs, 1)),
            100.0 * double(run.mCandidates.mReused) / double(candidateQueries),
            100.0 * double(run.mCandidates.mWalked) / double(candidateQueries),
            static_cast<unsigned long long>(run.mReusedColorings),
            static_cast<unsigned long long>(run.mColoredIslands),
            static_cast<unsigned long long>(run.mReusedSolveOrders), run.mSteps,
            double(run.mLoopPartsJoined) / run.mSteps, double(run.mJobsRun) / run.mSteps,
            double(run.mWorkerSleeps) / run.mSteps);
        means.push_back(run.mStep.mMean);
        p99s.push_back(run.mStep.mP99);
        maxes.push_back(run.mStep.mMax);
    }
    std::printf("%s threads=%u median of %zu: mean %.3f ms  p99 %.3f ms  max %.3f ms per step\n", inName,
                inThreads, inRuns.size(), tools::Median(means), tools::Median(p99s), tools::Median(maxes));
    return tools::Median(means);
}
} // namespace

int main(int inArgc, char** inArgv)
{
    tools::BenchOptions options;
    if (auto stop =
            tools::ParseBenchOptions(inArgc, inArgv, "cairn-bench-step: physics step figures",
                                     {"step_pile2k", "step_pyramid", "step_ragdolls"}, options, true,
                                     [](CLI::App& ioApp)
                                     {
                                         ioApp
                                             .add_option("--candidate-margin", gCandidateMargin,
                                                         "Broad-phase static candidate margin (m), 0 "
                                                         "turns the cache off")
                                             ->check(CLI::Range(0.0f, 100.0f));
                                         ioApp.add_flag("--queued-loops", gQueuedLoops,
                                                        "The job system's loops as a queued job per "
                                                        "part (its loop board off)");
                                         ioApp.add_option("--update-beside-from", gUpdateBesideFrom,
                                                          "Active bodies per helper thread from which the "
                                                          "broad-phase update runs beside the step "
                                                          "(PhysicsSettings::"
                                                          "mUpdateBesideStepMinActiveBodies)");
                                         ioApp
                                             .add_option("--min-chunks-per-thread", gMinChunksPerThread,
                                                         "Chunks each thread should find in the step's "
                                                         "loops, where the items allow "
                                                         "(PhysicsSettings::mMinChunksPerThread); 0: each "
                                                         "loop's own grain")
                                             ->check(CLI::Range(0u, 64u));
                                     }))
        return *stop;
    const int repetitions = options.mRepetitions;
    const std::string& only = options.mOnly;
    const std::vector<uint32_t>& threadCounts = options.mThreads;
#ifdef NDEBUG
    const char* buildType = "Release";
#else
    const char* buildType = "Debug (figures not representative)";
#endif
    std::printf("cairn-bench-step: build %s, %d repetitions%s, update beside from %u active bodies a helper, "
                "at least %u chunks a thread; %s; core-to-core round trip %.0f ns\n",
                buildType, repetitions, gQueuedLoops ? ", queued loops" : "", gUpdateBesideFrom,
                gMinChunksPerThread, tools::DescribeMachine().c_str(),
                tools::MeasureCoreToCoreRoundTripNanoseconds());
    auto speedUps = [&](const char* inName, const std::vector<double>& inMeans)
    {
        for (size_t t = 1; t < inMeans.size(); ++t)
            std::printf("%s speed-up %u -> %u threads: %.2fx\n", inName, threadCounts[0], threadCounts[t],
                        inMeans[0] / inMeans[t]);
    };

    if (only.empty() || only == "step_pile2k")
    {
        Result<SharedBenchData> data = LoadSharedBenchData();
        if (!data)
            std::printf("step_pile2k skipped: %s\n", data.GetError().mMessage.c_str());
        else
        {
            std::vector<double> means;
            for (uint32_t threads : threadCounts)
            {
                jobs::JobSystem jobSystem(JobSettings(threads));
                std::vector<RunResult> runs;
                for (int i = 0; i < repetitions; ++i)
                    runs.push_back(RunPile2k(data.Value(), jobSystem));
                means.push_back(Print("step_pile2k", threads, runs));
            }
            speedUps("step_pile2k", means);
        }
    }
    if (only.empty() || only == "step_pyramid")
    {
        std::vector<double> means;
        for (uint32_t threads : threadCounts)
        {
            jobs::JobSystem jobSystem(JobSettings(threads));
            std::vector<RunResult> runs;
            for (int i = 0; i < repetitions; ++i)
                runs.push_back(RunPyramid(jobSystem));
            means.push_back(Print("step_pyramid", threads, runs));
        }
        speedUps("step_pyramid", means);
    }
    if (only.empty() || only == "step_ragdolls")
    {
        std::vector<double> means;
        for (uint32_t threads : threadCounts)
        {
            jobs::JobSystem jobSystem(JobSettings(threads));
            std::vector<RunResult> runs;
            for (int i = 0; i < repetitions; ++i)
                runs.push_back(RunRagdolls(jobSystem));
            means.push_back(Print("step_ragdolls", threads, runs));
        }
        speedUps("step_ragdolls", means);
    }
    return 0;
}
