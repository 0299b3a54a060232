// Determinism of the parallel step: the same scene stepped 600 times gives bit-identical body states run
// after run with the same number of threads, and the same states with no job system and with 1, 2 and 4
// threads (pairs, contacts, waking and islands are made canonical, see PhysicsStep.h); and the same states
// on a scheduler that is not cairn::jobs, through the step's job interface (jobs::JobInterface). And the
// broad-phase update goes beside the step from fewer active bodies the more helper threads it has.

#include "SimulationFixture.h"
#include "cairn/jobs/JobInterface.h"
#include "common/MakePhysicsSystem.h"
#include "common/StaticFloor.h"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace cairn::test
{
using namespace cairn::physics;
namespace
{

struct BodyState
{
    Vec3 mPosition;
    Quat mRotation;
    Vec3 mLinearVelocity;
    Vec3 mAngularVelocity;
    bool mActive;
};

bool BitIdentical(const BodyState& inL, const BodyState& inR)
{
    auto same = [](const auto& inA, const auto& inB) { return std::memcmp(&inA, &inB, sizeof(inA)) == 0; };
    return same(inL.mPosition, inR.mPosition) && same(inL.mRotation.coeffs(), inR.mRotation.coeffs()) &&
           same(inL.mLinearVelocity, inR.mLinearVelocity) &&
           same(inL.mAngularVelocity, inR.mAngularVelocity) && inL.mActive == inR.mActive;
}

/// Adds the counts of inStep that show which paths a step took to ioSum.
void AddCounts(const StepStatistics& inStep, StepStatistics& ioSum)
{
    ioSum.mNumManifolds += inStep.mNumManifolds;
    ioSum.mNumIslands += inStep.mNumIslands;
    ioSum.mNumColoredIslands += inStep.mNumColoredIslands;
    ioSum.mLargestIsland = std::max(ioSum.mLargestIsland, inStep.mLargestIsland);
}

/// A pile of boxes and spheres falling onto a floor and a ramp, in several heaps (several islands, some
/// falling asleep, some woken by late arrivals), stepped 600 times.
/// inJobs: null for none. outStatistics: the step statistics summed over the steps.
std::vector<BodyState> RunPile(jobs::JobInterface* inJobs, bool inUpdateBesideStep = false,
                               StepStatistics* outStatistics = nullptr,
                               uint32_t inMinChunksPerThread = PhysicsSettings().mMinChunksPerThread)
{
    PhysicsSettings physicsSettings;
    physicsSettings.mMinChunksPerThread = inMinChunksPerThread;
    // The broad-phase rebuild beside the pair search on this small scene too (by default from 1,024 bodies)
    if (inUpdateBesideStep) physicsSettings.mUpdateBesideStepMinActiveBodies = 0;
    const std::unique_ptr<PhysicsSystem> system = MakePhysicsSystem(physicsSettings);
    BodyInterface& bodies = system->GetBodyInterface();
    const BodyCreationSettings floor = test::StaticFloorSettings(40.0f);
    (void)bodies.CreateAndAddBody(floor, Activation::DontActivate);
    BodyCreationSettings ramp = floor;
    ramp.mShape = BoxShape::Create(Vec3(6, 0.5f, 6)).Value();
    ramp.mPosition = Vec3(15, 2, 0);
    ramp.mRotation = Quat(Eigen::AngleAxisf(0.4f, Vec3::UnitZ()));
    (void)bodies.CreateAndAddBody(ramp, Activation::DontActivate);

    std::vector<BodyID> ids;
    const ShapeRef box = BoxShape::Create(Vec3(0.4f, 0.4f, 0.4f)).Value();
    const ShapeRef ball = SphereShape::Create(0.35f).Value();
    for (int heap = 0; heap < 4; ++heap)
        for (int i = 0; i < 80; ++i)
        {
            BodyCreationSettings settings;
            settings.mShape = (i % 3 == 0) ? ball : box;
            const float x = -15.0f + 10.0f * float(heap) + 0.3f * float(i % 4);
            settings.mPosition =
                Vec3(x, 0.5f + 0.9f * float(i / 4) + 0.2f * float(heap), 0.25f * float(i % 5));
            settings.mRotation = Quat(Eigen::AngleAxisf(0.13f * float(i), Vec3(1, 2, 0.5f).normalized()));
            settings.mMotionType = MotionType::Dynamic;
            settings.mObjectLayer = Layers::cMoving;
            ids.push_back(bodies.CreateAndAddBody(settings, Activation::Activate).Value());
        }
    for (int step = 0; step < 600; ++step)
    {
        const Status status =
            inJobs ? system->Update(1.0f / 60.0f, 1, *inJobs) : system->Update(1.0f / 60.0f);
        EXPECT_TRUE(status.IsOk());
        if (outStatistics != nullptr) AddCounts(system->GetLastStepStatistics(), *outStatistics);
        if (step == 400)
        {
            // A late arrival wakes a heap that may have gone to sleep
            BodyCreationSettings late;
            late.mShape = box;
            late.mPosition = Vec3(-15, 12, 0);
            late.mMotionType = MotionType::Dynamic;
            late.mObjectLayer = Layers::cMoving;
            ids.push_back(bodies.CreateAndAddBody(late, Activation::Activate).Value());
        }
    }
    std::vector<BodyState> states;
    for (const BodyID& id : ids)
        states.push_back({bodies.GetPosition(id).Value(), bodies.GetRotation(id).Value(),
                          bodies.GetLinearVelocity(id).Value(), bodies.GetAngularVelocity(id).Value(),
                          bodies.IsActive(id).Value()});
    return states;
}

/// The pile on a job system of inThreads threads (0: no job system).
std::vector<BodyState> RunPileOnThreads(uint32_t inThreads, bool inUpdateBesideStep = false)
{
    if (inThreads == 0) return RunPile(nullptr, inUpdateBesideStep);
    jobs::JobSystem::Settings settings;
    settings.mNumThreads = inThreads;
    jobs::JobSystem jobSystem(settings);
    return RunPile(&jobSystem, inUpdateBesideStep);
}

void ExpectIdentical(const std::vector<BodyState>& inExpected, const std::vector<BodyState>& inActual,
                     const char* inWhat)
{
    ASSERT_EQ(inExpected.size(), inActual.size());
    int differing = 0;
    for (size_t i = 0; i < inExpected.size(); ++i)
        if (!BitIdentical(inExpected[i], inActual[i]) && ++differing <= 3)
            ADD_FAILURE() << inWhat << ": body " << i << " differs: position "
                          << inExpected[i].mPosition.transpose() << " vs "
                          << inActual[i].mPosition.transpose();
    EXPECT_EQ(differing, 0) << inWhat;
}

TEST(StepDeterminismTest, SameThreadCountGivesBitIdenticalStates)
{
    ExpectIdentical(RunPileOnThreads(2), RunPileOnThreads(2), "2 threads, two runs");
}

TEST(StepDeterminismTest, ThreadCountDoesNotChangeTheResult)
{
    const std::vector<BodyState> reference = RunPileOnThreads(0);
    ExpectIdentical(reference, RunPileOnThreads(1), "1 job thread vs no job system");
    ExpectIdentical(reference, RunPileOnThreads(2), "2 threads vs no job system");
    ExpectIdentical(reference, RunPileOnThreads(4), "4 threads vs no job system");
    ExpectIdentical(reference, RunPileOnThreads(2, true),
                    "2 threads, broad-phase update beside the step, vs no job system");
}

/// The least a scheduler can be: a thread for every task and for every part of a loop but the caller's, each
/// joined when done. Counts what the step asked of it.
class ThreadPerTaskJobs : public jobs::JobInterface
{
public:
    explicit ThreadPerTaskJobs(uint32_t inThreads) : mThreads(inThreads) {}

    uint32_t GetNumThreads() const override { return mThreads; }
    void ParallelFor(uint32_t inCount, uint32_t inGrain, RangeFunction inFunction, void* inContext) override
    {
        mNumLoops.fetch_add(1, std::memory_order_relaxed); // Relaxed: a count, read after the threads joined
        if (inCount == mThreads && inGrain == 1)
            mNumLoopsOfAChunkPerThread.fetch_add(1, std::memory_order_relaxed);
        const uint32_t grain = std::max(1u, inGrain);
        std::atomic<uint32_t> next{0};
        auto work = [&]
        {
            // Relaxed: hands out each chunk once; the join orders the chunks' writes before the caller's
            // reads
            for (uint32_t begin; (begin = next.fetch_add(grain, std::memory_order_relaxed)) < inCount;)
                inFunction(begin, std::min(inCount, begin + grain), inContext);
        };
        std::vector<std::thread> helpers;
        for (uint32_t t = 1; t < mThreads; ++t)
            helpers.emplace_back(work);
        work();
        for (std::thread& helper : helpers)
            helper.join();
    }
    jobs::TaskHandle StartTask(const char* inName, TaskFunction inFunction, void* inContext) override
    {
        std::lock_guard lock(mMutex);
        const uint64_t id = ++mNumTasks;
        ++mNumTasksNamed[inName];
        mTasks.emplace(id, Task{std::thread(inFunction, inContext), GetNumLoopsOfAChunkPerThread()});
        return {id};
    }
    void FinishTask(jobs::TaskHandle inTask) override
    {
        Task finished;
        {
            std::lock_guard lock(mMutex);
            const auto task = mTasks.find(inTask.mValue);
            ASSERT_NE(task, mTasks.end()) << "a task finished twice or never started";
            finished = std::move(task->second);
            mTasks.erase(task);
            mStagesBesideTasks += GetNumLoopsOfAChunkPerThread() - finished.mStagesBefore;
        }
        finished.mThread.join();
    }

    uint64_t GetNumLoops() const { return mNumLoops.load(std::memory_order_relaxed); } // Relaxed: a count
    /// Loops of one chunk per thread: StepScheduler::RunStages' (a colored island solved by every thread).
    uint64_t GetNumLoopsOfAChunkPerThread() const
    {
        return mNumLoopsOfAChunkPerThread.load(std::memory_order_relaxed); // Relaxed: a count
    }
    uint64_t GetNumTasks() const
    {
        std::lock_guard lock(mMutex);
        return mNumTasks;
    }
    /// Tasks started under this name (the step's: "broad-phase update").
    uint64_t GetNumTasks(const std::string& inName) const
    {
        std::lock_guard lock(mMutex);
        const auto named = mNumTasksNamed.find(inName);
        return named == mNumTasksNamed.end() ? 0 : named->second;
    }
    size_t GetNumUnfinished() const
    {
        std::lock_guard lock(mMutex);
        return mTasks.size();
    }
    /// Loops of one chunk per thread (stages) that began between a task's start and its finish: the step's
    /// solve, run while its broad-phase update was outstanding.
    uint64_t GetNumStagesBesideTasks() const
    {
        std::lock_guard lock(mMutex);
        return mStagesBesideTasks;
    }

private:
    struct Task
    {
        std::thread mThread;
        uint64_t mStagesBefore = 0; ///< GetNumLoopsOfAChunkPerThread at its start
    };
    const uint32_t mThreads;
    std::atomic<uint64_t> mNumLoops{0};
    std::atomic<uint64_t> mNumLoopsOfAChunkPerThread{0};
    mutable std::mutex mMutex;       ///< Guards mTasks, the counts below: any thread starts tasks
    std::map<uint64_t, Task> mTasks; ///< Started, not yet finished
    uint64_t mNumTasks = 0;          ///< Started in all
    std::map<std::string, uint64_t> mNumTasksNamed;
    uint64_t mStagesBesideTasks = 0;
};

TEST(StepDeterminismTest, AnotherSchedulerThroughTheJobInterfaceGivesTheSameStates)
{
    StepStatistics counts;
    const std::vector<BodyState> reference = RunPile(nullptr, false, &counts);
    // The pile has islands the step colors, some large enough for every thread at once (the stages)
    ASSERT_GT(counts.mNumColoredIslands, 0u);
    for (const uint32_t threads : {2u, 3u})
    {
        ThreadPerTaskJobs jobs(threads);
        ExpectIdentical(reference, RunPile(&jobs, true), "threads per task vs no job system");
        EXPECT_GT(jobs.GetNumLoops(), 600u) << "the step's loops went to the scheduler";
        EXPECT_EQ(jobs.GetNumTasks("broad-phase update"), 600u) << "a task beside every step";
        EXPECT_GT(jobs.GetNumLoopsOfAChunkPerThread(), 0u) << "colored islands solved by every thread";
        // The step waits for its update only before the finish: the solve's stages run beside it
        EXPECT_GT(jobs.GetNumStagesBesideTasks(), 0u) << "the update was waited for before the solve";
        EXPECT_EQ(jobs.GetNumUnfinished(), 0u);
    }
}

/// Says it has inThreads threads, and runs each loop on the caller, its chunks from the last to the first
/// (tasks each on a thread of their own, as ThreadPerTaskJobs): the step cuts its loops for that many threads
/// (StepScheduler::GrainFor), and no chunk may depend on the chunks before it having run. Counts the chunks
/// of loops over items in groups (a grain over 1: GrainFor's; the loops of a part per item, such as a stage's
/// parts, do not change with it).
class ClaimedThreadsJobs final : public ThreadPerTaskJobs
{
public:
    using ThreadPerTaskJobs::ThreadPerTaskJobs;
    void ParallelFor(uint32_t inCount, uint32_t inGrain, RangeFunction inFunction, void* inContext) override
    {
        const uint32_t grain = std::max(1u, inGrain);
        const uint32_t chunks = (inCount + grain - 1) / grain;
        if (grain > 1) mNumChunks += chunks;
        for (uint32_t chunk = chunks; chunk-- > 0;)
            inFunction(chunk * grain, std::min(inCount, chunk * grain + grain), inContext);
    }
    uint64_t GetNumChunks() const { return mNumChunks; }

private:
    uint64_t mNumChunks = 0; ///< The loops run on the updating thread alone
};

TEST(StepDeterminismTest, LoopsCutForManyThreadsGiveTheSameStates)
{
    const std::vector<BodyState> reference = RunPile(nullptr);
    ClaimedThreadsJobs cut(16), whole(16);
    ExpectIdentical(reference, RunPile(&cut), "loops cut for 16 threads vs no job system");
    ExpectIdentical(reference, RunPile(&whole, false, nullptr, 0),
                    "each loop's own grain on 16 threads vs no job system");
    // The pile's 321 bodies make a few chunks a loop at the loops' own grains
    EXPECT_GT(cut.GetNumChunks(), 3 * whole.GetNumChunks()) << "the loops were cut finer for 16 threads";
}

/// Steps of a world of inBodies falling boxes (none asleep) whose update goes beside the step from
/// inMinActive active bodies a helper, on a scheduler of inThreads threads: the updates it ran beside, as
/// tasks.
uint64_t UpdatesBesideTheStep(uint32_t inBodies, uint32_t inMinActive, uint32_t inThreads, int inSteps)
{
    PhysicsSettings settings;
    settings.mAllowSleeping = false;
    settings.mUpdateBesideStepMinActiveBodies = inMinActive;
    const std::unique_ptr<PhysicsSystem> system = MakePhysicsSystem(settings);
    BodyInterface& bodies = system->GetBodyInterface();
    (void)bodies.CreateAndAddBody(test::StaticFloorSettings(40.0f), Activation::DontActivate);
    const ShapeRef box = BoxShape::Create(Vec3(0.4f, 0.4f, 0.4f)).Value();
    for (uint32_t i = 0; i < inBodies; ++i)
    {
        BodyCreationSettings falling;
        falling.mShape = box;
        falling.mPosition = Vec3(-15.0f + 1.5f * float(i % 20), 3.0f + 1.5f * float(i / 20), 0.0f);
        falling.mMotionType = MotionType::Dynamic;
        falling.mObjectLayer = Layers::cMoving;
        EXPECT_TRUE(bodies.CreateAndAddBody(falling, Activation::Activate).IsOk());
    }
    ThreadPerTaskJobs jobs(inThreads);
    for (int step = 0; step < inSteps; ++step)
        EXPECT_TRUE(system->Update(1.0f / 60.0f, 1, jobs).IsOk());
    EXPECT_EQ(jobs.GetNumUnfinished(), 0u);
    return jobs.GetNumTasks("broad-phase update");
}

TEST(StepDeterminismTest, TheUpdateGoesBesideTheStepFromFewerActiveBodiesWithMoreHelpers)
{
    // 100 active bodies against a bar of 150 a helper: 100 on 2 threads (one helper), 200 on 3, 300 on 4
    constexpr int cSteps = 10;
    EXPECT_EQ(UpdatesBesideTheStep(100, 150, 2, cSteps), 0u) << "one helper: the step updates first, itself";
    EXPECT_EQ(UpdatesBesideTheStep(100, 150, 3, cSteps), uint64_t(cSteps))
        << "two helpers: beside every step";
    EXPECT_EQ(UpdatesBesideTheStep(100, 150, 4, cSteps), uint64_t(cSteps));
    EXPECT_EQ(UpdatesBesideTheStep(100, 0, 2, cSteps), uint64_t(cSteps))
        << "a bar of 0: beside whenever it may";
}

} // namespace
} // namespace cairn::test
