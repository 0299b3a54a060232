// cairn-bench-query-latency: how long a query from another thread takes while the physics step runs, against
// while it is idle, and whether it waited for a lock; and the same for a write.
//
// The main thread steps step_pyramid (SPEC.md: 1,240 awake boxes, 1/60 s, no job system) back to back for
// 1 s, then sleeps 0.5 s, and again, for --seconds. A query thread issues queries meanwhile, each after a
// random busy wait of 0 to --max-wait-us, so they land at random moments of the step and of the idle time.
// The query kinds, in turn:
//  ray_pyramid         CastRayClosest from 24 m off the pyramid's -x side, through it (exact shapes)
//  sphere_overlap      CollideSphere, radius 1.5 m, inside the pyramid
//  box_overlap         CollideAABox, a 4 m cube, inside the pyramid
//  ray_static          CastRayClosest straight down onto the floor beside the pyramid: only a static body
//  capsule_cast        CastShapeClosest of a standing capsule (radius 0.4 m, 1.8 m tall) along ray_pyramid's
//                      path, 1 m higher: a character's probe, a ray's candidates and more, each one swept
//  character_walk      CharacterController::Update of a standing capsule (the same), one 1/60 s frame of a
//                      walk at 3 m/s from 2-6 m off the pyramid's -x face into it: it meets the boxes and
//                      slides along them (a character's frame: a few sweeps and overlaps); every 90 frames it
//                      is put back at a new start
//  tile_collect        GeometryCollector::FindBodies + CollectTriangles over the 12.8 m navmesh tile
//                      x, z in [-12.8, 0] (a quarter of the pyramid), full height, awake boxes included
// and a write, from a third thread that sleeps 0 to --write-interval-us between writes:
//  write_set_position  BodyInterface::SetPosition of a kinematic box in a corner of the floor. A write takes
//                      its body's mutex, which the step holds for all of its length, so it may wait for the
//                      step; measured, with no target. It has its own thread because with steps back to back
//                      a write can wait for many of them: the step takes its mutexes again within
//                      microseconds of letting them go, mostly before the woken writer runs (on the 2-core
//                      machine writes waited up to 100-150 ms, 20-30 steps, beside the query thread, and a
//                      whole 1 s stepping phase with --only write_set_position, when the writer wakes on an
//                      idle core); on the query thread such a wait would stop the queries. The stepping
//                      thread reads its CPU clock between steps (a few microseconds), which gives a waiting
//                      write some chance: read the write's figures as "with a small gap between steps".
// A query sample is "running" when the step flag (up around each Update) was up at its start and at its
// end, in one stepping phase; a write is "running" when the flag was up at its start (so that a write the
// steps keep waiting counts where it began, however late it ends). A sample is "idle" when the flag was down
// at both ends and the stepping thread was in one idle phase. Mixed ones are dropped (and counted). A running
// sample is dropped too when the stepping thread was preempted (switched out involuntarily and off its core
// for more than cPreemptedStepMicros beyond its own lock waits) in a step it overlapped: on a busy machine
// that thread can lose its core right after the step let go of the body mutexes and before the flag comes
// down, and queries labelled "running" then meet a world that nobody steps (seen on this 2-core machine
// while another build ran: most body-lock queries "running", and waiting for nothing).
// A sample "waited" when its thread's lock-wait counter (LockWaits.h) grew during it. Once per mode:
// published (queries read published poses, the default) and bodylocks (PhysicsSettings::mQueryReads =
// BodyLocks, each candidate read under its body lock: the "before"). GeometryCollector has no body-lock
// mode: tile_collect reads published poses in both.
//
// How to read it: per kind, p50 / p99 / max in microseconds with the step running and idle, the ratio of
// the p99s, and how many of those samples waited. "on-core p99" is the p99 of the thread's CPU time over the
// same samples and "preempted" counts those during which the scheduler gave its core to another thread: a
// p99 that grows while the on-core p99 does not is time off the core (blocked on a lock, or preempted: the
// stepping and query threads keep both cores of a 2-core machine busy, so anything else that runs takes
// one). The step line gives the steps' times, their own waits for the body mutexes (a query or write holding
// one when a step starts) and how many steps were preempted. The verdict line checks the targets: for every
// query kind (not the write) p99 running <= 2x p99 idle, and no query (dropped samples included) waited for
// a lock. The checksum line (hits, bodies, triangles, writes per kind, over every sample) proves the work
// was done; the tile line shows how much a tile collection read (there is no retry to count any more: the
// collector reads published poses and never tries again). With --repetitions N each mode builds N fresh
// worlds and the percentiles are over all of their samples.
//
// Threads: the main thread steps; one std::thread queries, one writes. They share the world and the four
// atomics of StepSignals; each fills its own kinds' results, handed back by join().

#include "cairn/navmesh/GeometryCollector.h"
#include "cairn/physics/LockWaits.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/character/CharacterController.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "common/BenchOptions.h"
#include "common/BenchScenes.h"
#include "common/FrameTimes.h"
#include "common/MachineInfo.h"
#include "common/Mix64.h"
#include "common/PhysicsSystemOrExit.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <optional>
#include <string>
#include <sys/resource.h>
#include <thread>
#include <time.h>
#include <vector>

using namespace cairn;
using namespace cairn::physics;
using Clock = std::chrono::steady_clock;

namespace
{

enum class Kind : uint8_t
{
    RayPyramid,
    SphereOverlap,
    BoxOverlap,
    RayStatic,
    CapsuleCast,
    CharacterWalk,
    TileCollect,
    WriteSetPosition,
};
constexpr size_t cNumKinds = 8;
constexpr std::array<const char*, cNumKinds> cKindNames = {
    "ray_pyramid",  "sphere_overlap", "box_overlap",  "ray_static",
    "capsule_cast", "character_walk", "tile_collect", "write_set_position"};
/// What the checksum counts of each kind
constexpr std::array<const char*, cNumKinds> cKindCounts = {"hits", "bodies",   "bodies", "hits",
                                                            "hits", "contacts", "bodies", "ok"};
/// character_walk: frames of a walk before the character is put back at a new start
constexpr uint64_t cCharacterWalkFrames = 90;

/// The targets are on queries; a write may wait for the step
bool IsQuery(Kind inKind)
{
    return inKind != Kind::WriteSetPosition;
}

/// The stepping thread's rhythm: long enough runs of back-to-back steps that the query thread lands in many
/// steps, and idle stretches long enough to give as many idle samples as the steps' share allows.
constexpr auto cRunningPhase = std::chrono::milliseconds(1000);
constexpr auto cIdlePhase = std::chrono::milliseconds(500);
/// Steps before the other threads start: the layers fall their 0.5 m and the first broad-phase rebuilds
/// are done, so the measured steps are the pyramid's steady ones.
constexpr int cWarmUpSteps = 60;
/// A step whose thread was switched out involuntarily and off its core longer than this (beyond its own
/// lock waits) makes the running samples it overlaps doubtful (see the top). A wake-up of another thread
/// on its core costs a few microseconds; a lost time slice, milliseconds.
constexpr double cPreemptedStepMicros = 50.0;

/// The navmesh tile collected: the tile grid's tile (-1, -1) of 12.8 m, over a quarter of the pyramid, from
/// under the floor's top to above the pyramid's highest box.
const AABB cTileBox(Vec3(-12.8f, -2.0f, -12.8f), Vec3(0.0f, tools::cPyramidTop + 3.0f, 0.0f));
/// Where the kinematic box that the writes move lives: a floor corner, away from every query.
const Vec3 cKinematicHome(-40.0f, 1.0f, -40.0f);

struct Settings
{
    double mSeconds = 8.0;           ///< Per mode and repetition
    std::string mMode = "both";      ///< published, bodylocks or both
    int mMaxWaitMicros = 300;        ///< The random busy wait before each query: 0 to this
    int mWriteIntervalMicros = 2000; ///< The random sleep before each write: 0 to this
};

/// Random values in [inMin, inMax) from Mix64 over a counter: the same query places on every machine.
class Random
{
public:
    explicit Random(uint64_t inSeed) : mState(inSeed) {}
    float Next(float inMin, float inMax)
    {
        const double unit = double(tools::Mix64(++mState) >> 11) * 0x1.0p-53; // 53 bits: [0, 1)
        return inMin + float(unit) * (inMax - inMin);
    }

private:
    uint64_t mState;
};

/// The calling thread's CPU time and involuntary context switches (Linux): an involuntary switch is the
/// scheduler taking the thread's core for another thread (blocking on a lock is a voluntary one).
struct ThreadTimes
{
    double mCpuUs = 0.0;
    int64_t mInvoluntarySwitches = 0;
};

ThreadTimes ReadThreadTimes()
{
    ThreadTimes times;
    rusage usage{};
    timespec cpu{};
    if (getrusage(RUSAGE_THREAD, &usage) == 0) times.mInvoluntarySwitches = int64_t(usage.ru_nivcsw);
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu) == 0)
        times.mCpuUs = double(cpu.tv_sec) * 1.0e6 + double(cpu.tv_nsec) / 1.0e3;
    return times;
}

/// One timed query or write.
struct Sample
{
    double mWallUs = 0.0;
    double mCpuUs = 0.0;     ///< Its thread's CPU time over it (the clock reads are outside it)
    bool mWaited = false;    ///< Its thread's lock-wait counter grew
    bool mPreempted = false; ///< Its thread was switched out involuntarily (another thread took its core)
    /// The steps finished when it started and when it ended: the steps it overlapped, for dropping those
    /// whose stepping thread was preempted (see RunOnce)
    uint32_t mStepsBefore = 0, mStepsAfter = 0;
};

/// One kind's samples; filled by the one thread that runs the kind.
struct KindResult
{
    std::vector<Sample> mRunning, mIdle;
    uint64_t mCount = 0;  ///< The checksum's count (cKindCounts), over every sample, dropped ones too
    uint64_t mErrors = 0; ///< Queries or writes that returned an error (there should be none)
    /// Every sample, dropped ones too, and how many of them waited for a lock: the target is on all queries
    uint64_t mSamples = 0, mWaited = 0;
    uint64_t mDroppedMixed = 0;                   ///< Neither wholly running nor wholly idle
    uint64_t mDroppedPreempted = 0;               ///< Running, but in a step whose thread was preempted
    std::vector<Sample> mRunningInPreemptedSteps; ///< Those dropped samples, for the p99 printed with them
};

struct ModeResult
{
    std::array<KindResult, cNumKinds> mKinds;
    uint64_t mTileCollections = 0, mTileBodies = 0, mTileTriangles = 0; ///< The query thread's
    std::vector<double> mStepMs;  ///< Each step's wall time; this and the rest: the stepping thread's
    double mStepLockWaitMs = 0.0; ///< The steps' own waits for body mutexes (a query or write holding one)
    uint64_t mStepsPreempted = 0; ///< Steps whose thread lost its core (cPreemptedStepMicros)
    double mRunningSeconds = 0.0, mIdleSeconds = 0.0;
};

/// What the stepping thread tells the other two. They label samples and end the loops; no data is handed
/// over through them (the results come back by join()), so every access is relaxed.
struct StepSignals
{
    std::atomic<bool> mStepping{false};  ///< Up around each Update
    std::atomic<uint32_t> mPhase{0};     ///< Even: a stepping phase; odd: an idle one; counts phases
    std::atomic<uint32_t> mStepsDone{0}; ///< Steps finished in this world (after the warm-up)
    std::atomic<bool> mStop{false};
};

/// Times inWork (a query or a write: returns false on an error) and files its sample under running or idle,
/// or drops it. inRunningByStart: a sample that began during a step is running, however it ended (writes).
template <class Work>
void TimeSample(const StepSignals& inSignals, bool inRunningByStart, KindResult& ioResult, Work&& inWork)
{
    const ThreadTimes timesBefore = ReadThreadTimes();
    // Relaxed, all four: labels; a step lasts milliseconds, so a flag seen a few nanoseconds late labels
    // nothing measurably wrong
    const uint32_t phaseBefore = inSignals.mPhase.load(std::memory_order_relaxed);
    const bool steppingBefore = inSignals.mStepping.load(std::memory_order_relaxed);
    const uint32_t stepsBefore = inSignals.mStepsDone.load(std::memory_order_relaxed);
    const uint64_t waitBefore = GetThisThreadLockWaitNanoseconds();
    const Clock::time_point start = Clock::now();
    const bool ok = inWork();
    const Clock::time_point end = Clock::now();
    const uint64_t waitAfter = GetThisThreadLockWaitNanoseconds();
    const bool steppingAfter = inSignals.mStepping.load(std::memory_order_relaxed); // Labels, as above
    const uint32_t phaseAfter = inSignals.mPhase.load(std::memory_order_relaxed);
    const uint32_t stepsAfter = inSignals.mStepsDone.load(std::memory_order_relaxed);
    const ThreadTimes timesAfter = ReadThreadTimes();

    Sample sample;
    sample.mWallUs = std::chrono::duration<double, std::micro>(end - start).count();
    sample.mCpuUs = timesAfter.mCpuUs - timesBefore.mCpuUs;
    sample.mWaited = waitAfter > waitBefore;
    sample.mPreempted = timesAfter.mInvoluntarySwitches != timesBefore.mInvoluntarySwitches;
    sample.mStepsBefore = stepsBefore;
    sample.mStepsAfter = stepsAfter;
    ++ioResult.mSamples;
    ioResult.mWaited += sample.mWaited ? 1 : 0;
    ioResult.mErrors += ok ? 0 : 1;
    const bool samePhase = phaseBefore == phaseAfter;
    if (steppingBefore && (inRunningByStart || (steppingAfter && samePhase)))
        ioResult.mRunning.push_back(sample);
    else if (!steppingBefore && !steppingAfter && samePhase && (phaseBefore & 1u) != 0)
        ioResult.mIdle.push_back(sample);
    else
        ++ioResult.mDroppedMixed;
}

/// A query's input, drawn before it is timed.
struct QueryInput
{
    RayCast mRay;
    Vec3 mPoint = Vec3::Zero();
};

QueryInput DrawInput(Kind inKind, Random& ioRandom)
{
    constexpr float cInsideMin = tools::cPyramidFootprintMin + 2.0f,
                    cInsideMax = tools::cPyramidFootprintMax - 2.0f;
    QueryInput input;
    switch (inKind)
    {
    case Kind::RayPyramid:
    case Kind::CapsuleCast:
        // From 24 m off the pyramid's -x face, level with its lower half, 60 m across it
        input.mRay.mOrigin = Vec3(tools::cPyramidFootprintMin - 24.0f, ioRandom.Next(0.5f, 12.0f),
                                  ioRandom.Next(cInsideMin, cInsideMax));
        input.mRay.mDirection = Vec3(60.0f, ioRandom.Next(-2.0f, 2.0f), ioRandom.Next(-2.0f, 2.0f));
        // The capsule starts clear of the floor (its foot 0.1 m up at the least), as a character stands
        if (inKind == Kind::CapsuleCast) input.mRay.mOrigin.y() += 1.0f;
        break;
    case Kind::CharacterWalk:
        // On the floor (the capsule's foot 2 cm up), 2-6 m off the pyramid's -x face
        input.mPoint = Vec3(tools::cPyramidFootprintMin - ioRandom.Next(2.0f, 6.0f), 0.92f,
                            ioRandom.Next(cInsideMin, cInsideMax));
        input.mRay.mDirection = Vec3(3.0f, 0.0f, ioRandom.Next(-1.0f, 1.0f));
        break;
    case Kind::SphereOverlap:
    case Kind::BoxOverlap:
        input.mPoint = Vec3(ioRandom.Next(cInsideMin, cInsideMax), ioRandom.Next(0.5f, 14.0f),
                            ioRandom.Next(cInsideMin, cInsideMax));
        break;
    case Kind::RayStatic:
        // Down onto the floor between the pyramid's +x face and the floor's edge: the floor is the only body
        input.mRay.mOrigin = Vec3(ioRandom.Next(tools::cPyramidFootprintMax + 6.0f, 45.0f), 10.0f,
                                  ioRandom.Next(-45.0f, 45.0f));
        input.mRay.mDirection = Vec3(0.0f, -20.0f, 0.0f);
        break;
    case Kind::TileCollect:
        break; // Always the same tile: the same work each time
    case Kind::WriteSetPosition:
        input.mPoint = cKinematicHome + Vec3(ioRandom.Next(-2.0f, 2.0f), 0.0f, ioRandom.Next(-2.0f, 2.0f));
        break;
    }
    return input;
}

CharacterController MakeCharacter(const PhysicsSystem& inPhysics, const ShapeRef& inCapsule)
{
    CharacterSettings settings;
    settings.mShape = inCapsule;
    // Valid settings and a valid place: Create can not refuse them
    return CharacterController::Create(inPhysics, settings,
                                       Vec3(tools::cPyramidFootprintMin - 4.0f, 0.92f, 0.0f))
        .Value();
}

/// What the query thread works with; its buffers are reused, so a query's time is not an allocation's.
struct QueryContext
{
    const WorldQuery& mQuery;
    const navmesh::GeometryCollector mCollector;
    const ShapeRef mCapsule = CapsuleShape::Create(0.5f, 0.4f).Value();
    CharacterController mCharacter;
    uint64_t mCharacterFrames = 0;
    std::vector<BodyID> mBodies;
    navmesh::TileGeometry mGeometry;
    navmesh::NavMeshInclusion mInclusion;

    explicit QueryContext(const PhysicsSystem& inPhysics)
        : mQuery(inPhysics.GetWorldQuery()),
          mCollector(inPhysics.GetBodyManager(), inPhysics.GetBroadPhase()),
          mCharacter(MakeCharacter(inPhysics, mCapsule))
    {
        mInclusion.mAwakeDynamic = true; // The pyramid's boxes are all awake: collect them
    }
};

/// Runs one query. outCount: what the checksum counts of it; outTriangles: a tile's triangles. False when
/// it returned an error.
bool RunQuery(Kind inKind, const QueryInput& inInput, QueryContext& ioContext, uint64_t& outCount,
              uint64_t& outTriangles)
{
    outCount = 0;
    outTriangles = 0;
    switch (inKind)
    {
    case Kind::RayPyramid:
    case Kind::RayStatic:
    {
        const Result<std::optional<RayCastResult>> hit = ioContext.mQuery.CastRayClosest(inInput.mRay);
        if (!hit) return false;
        outCount = hit.Value().has_value() ? 1 : 0;
        return true;
    }
    case Kind::CapsuleCast:
    {
        const Result<std::optional<ShapeCastResult>> hit = ioContext.mQuery.CastShapeClosest(
            *ioContext.mCapsule, {inInput.mRay.mOrigin, Quat::Identity()}, inInput.mRay.mDirection);
        if (!hit) return false;
        outCount = hit.Value().has_value() ? 1 : 0;
        return true;
    }
    case Kind::CharacterWalk:
    {
        CharacterController& character = ioContext.mCharacter;
        if (ioContext.mCharacterFrames++ % cCharacterWalkFrames == 0 &&
            !character.SetPosition(inInput.mPoint))
            return false;
        Vec3 velocity = inInput.mRay.mDirection;
        velocity.y() = character.GetLinearVelocity().y();
        if (!character.SetLinearVelocity(velocity) ||
            !character.Update(1.0f / 60.0f, Vec3(0.0f, -9.81f, 0.0f)))
            return false;
        outCount = character.GetContacts().size();
        return true;
    }
    case Kind::SphereOverlap:
        if (!ioContext.mQuery.CollideSphere(inInput.mPoint, 1.5f, ioContext.mBodies)) return false;
        outCount = ioContext.mBodies.size();
        return true;
    case Kind::BoxOverlap:
        if (!ioContext.mQuery.CollideAABox(AABB::FromCenterExtent(inInput.mPoint, Vec3::Constant(2.0f)),
                                           ioContext.mBodies))
            return false;
        outCount = ioContext.mBodies.size();
        return true;
    case Kind::TileCollect:
    {
        ioContext.mGeometry.Clear();
        navmesh::CollectStats stats;
        ioContext.mCollector.FindBodies(cTileBox, ioContext.mInclusion, ioContext.mBodies);
        ioContext.mCollector.CollectTriangles(cTileBox, ioContext.mInclusion, ioContext.mBodies,
                                              ioContext.mGeometry, stats);
        outCount = stats.mBodies;
        outTriangles = stats.mTriangles;
        return true;
    }
    case Kind::WriteSetPosition:
        break; // Not a query: WriteLoop
    }
    return false;
}

/// The query thread: one query after another, each after a random wait, until the stepping thread stops it.
void QueryLoop(const PhysicsSystem& inPhysics, const std::vector<Kind>& inKinds, int inMaxWaitMicros,
               const StepSignals& inSignals, uint64_t inSeed, ModeResult& ioResult)
{
    QueryContext context(inPhysics);
    Random random(inSeed);
    uint64_t count = 0, triangles = 0;
    // Once each, untimed: the thread-local buffers of the queries and the collector grow to size here
    for (Kind kind : inKinds)
        (void)RunQuery(kind, DrawInput(kind, random), context, count, triangles);
    for (size_t turn = 0; !inSignals.mStop.load(std::memory_order_relaxed); ++turn) // Only ends the loop
    {
        const Kind kind = inKinds[turn % inKinds.size()];
        const QueryInput input = DrawInput(kind, random);
        // A busy wait, not a sleep: the query starts at a random moment with this thread already on its core,
        // so no wake-up latency enters either the running or the idle figures
        const Clock::time_point until =
            Clock::now() +
            std::chrono::nanoseconds(int64_t(random.Next(0.0f, 1000.0f * float(inMaxWaitMicros))));
        while (Clock::now() < until)
        {
        }
        KindResult& result = ioResult.mKinds[size_t(kind)];
        TimeSample(inSignals, false, result,
                   [&] { return RunQuery(kind, input, context, count, triangles); });
        result.mCount += count;
        if (kind == Kind::TileCollect)
        {
            ++ioResult.mTileCollections;
            ioResult.mTileBodies += count;
            ioResult.mTileTriangles += triangles;
        }
    }
}

/// The write thread: a SetPosition of the kinematic box after each random sleep, until stopped. It sleeps
/// (it does not spin as the query thread does) so that it leaves both cores to the step and the queries.
void WriteLoop(BodyInterface& ioBodies, BodyID inKinematic, int inIntervalMicros,
               const StepSignals& inSignals, uint64_t inSeed, ModeResult& ioResult)
{
    Random random(inSeed);
    KindResult& result = ioResult.mKinds[size_t(Kind::WriteSetPosition)];
    while (!inSignals.mStop.load(std::memory_order_relaxed)) // Only ends the loop
    {
        std::this_thread::sleep_for(
            std::chrono::nanoseconds(int64_t(random.Next(0.0f, 1000.0f * float(inIntervalMicros)))));
        const QueryInput input = DrawInput(Kind::WriteSetPosition, random);
        TimeSample(
            inSignals, true, result,
            [&] { return bool(ioBodies.SetPosition(inKinematic, input.mPoint, Activation::DontActivate)); });
        ++result.mCount;
    }
}

/// One world, stepped, queried and written for inSettings.mSeconds; adds its samples to ioResult.
void RunOnce(QueryReads inReads, const Settings& inSettings, const std::vector<Kind>& inKinds,
             uint64_t inSeed, ModeResult& ioResult)
{
    PhysicsSettings physicsSettings = tools::BenchSettings(tools::cPyramidAllowSleeping);
    physicsSettings.mQueryReads = inReads;
    const std::unique_ptr<PhysicsSystem> physics =
        tools::CreatePhysicsSystemOrExit("cairn-bench-query-latency", physicsSettings);
    BodyInterface& bodies = physics->GetBodyInterface();
    (void)tools::AddPyramid(bodies);
    const BodyID kinematic = bodies
                                 .CreateAndAddBody(tools::BoxSettings(cKinematicHome, Vec3(1, 1, 1), 0,
                                                                      MotionType::Kinematic, 0.2f),
                                                   Activation::DontActivate)
                                 .Value();
    for (int step = 0; step < cWarmUpSteps; ++step)
        (void)physics->Update(tools::cPyramidStepSeconds);

    std::vector<Kind> queryKinds;
    std::copy_if(inKinds.begin(), inKinds.end(), std::back_inserter(queryKinds), IsQuery);
    const bool writes = queryKinds.size() < inKinds.size();
    // Where this world's running samples start in ioResult (the filter below looks at this world's only)
    std::array<size_t, cNumKinds> firstRunning{};
    for (size_t kind = 0; kind < cNumKinds; ++kind)
        firstRunning[kind] = ioResult.mKinds[kind].mRunning.size();

    StepSignals signals;
    // A thread's start publishes the world built above to it; its join publishes its samples back
    std::thread queryThread, writeThread;
    if (!queryKinds.empty())
        queryThread = std::thread(
            [&] { QueryLoop(*physics, queryKinds, inSettings.mMaxWaitMicros, signals, inSeed, ioResult); });
    if (writes)
        writeThread = std::thread(
            [&]
            { WriteLoop(bodies, kinematic, inSettings.mWriteIntervalMicros, signals, ~inSeed, ioResult); });

    std::vector<bool> stepPreempted; ///< Per step of this world
    const Clock::time_point finish = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                        std::chrono::duration<double>(inSettings.mSeconds));
    Status stepStatus = Status::Ok(); // The first failed step's error, which ends the run
    while (Clock::now() < finish && stepStatus)
    {
        const Clock::time_point runStart = Clock::now();
        const Clock::time_point runEnd = std::min(runStart + cRunningPhase, finish);
        while (Clock::now() < runEnd)
        {
            const ThreadTimes timesBefore = ReadThreadTimes();
            const Clock::time_point stepStart = Clock::now();
            signals.mStepping.store(true, std::memory_order_relaxed); // A label (see StepSignals)
            const Status status = physics->Update(tools::cPyramidStepSeconds);
            signals.mStepping.store(false, std::memory_order_relaxed); // A label (see StepSignals)
            const Clock::time_point stepEnd = Clock::now();
            const ThreadTimes timesAfter = ReadThreadTimes();
            const double wallUs = std::chrono::duration<double, std::micro>(stepEnd - stepStart).count();
            const double lockWaitMs = physics->GetLastStepStatistics().mLockWaitMs;
            const double offCoreUs = wallUs - (timesAfter.mCpuUs - timesBefore.mCpuUs) - 1000.0 * lockWaitMs;
            stepPreempted.push_back(timesAfter.mInvoluntarySwitches != timesBefore.mInvoluntarySwitches &&
                                    offCoreUs > cPreemptedStepMicros);
            ioResult.mStepsPreempted += stepPreempted.back() ? 1 : 0;
            ioResult.mStepMs.push_back(wallUs / 1000.0);
            ioResult.mStepLockWaitMs += lockWaitMs;
            signals.mStepsDone.fetch_add(1, std::memory_order_relaxed); // A label (see StepSignals)
            if (!status)
            {
                stepStatus = status;
                break;
            }
        }
        const Clock::time_point idleStart = Clock::now();
        ioResult.mRunningSeconds += std::chrono::duration<double>(idleStart - runStart).count();
        if (idleStart >= finish || !stepStatus) break;
        signals.mPhase.fetch_add(1, std::memory_order_relaxed); // Idle now; a label (see StepSignals)
        std::this_thread::sleep_until(std::min(idleStart + cIdlePhase, finish));
        signals.mPhase.fetch_add(1, std::memory_order_relaxed); // Stepping again; a label
        ioResult.mIdleSeconds += std::chrono::duration<double>(Clock::now() - idleStart).count();
    }
    signals.mStop.store(true, std::memory_order_relaxed); // Ends the loops; join() hands the samples over
    if (queryThread.joinable()) queryThread.join();
    if (writeThread.joinable()) writeThread.join();
    if (!stepStatus)
    {
        std::fprintf(stderr, "cairn-bench-query-latency: the step failed: %s\n",
                     stepStatus.GetError().mMessage.c_str());
        std::exit(1);
    }

    // A running sample met the steps from mStepsBefore (the one under way at its start) to mStepsAfter;
    // drop it when the stepping thread was preempted in any of them
    const auto overlapsPreempted = [&](const Sample& inSample)
    {
        for (uint32_t step = inSample.mStepsBefore; step <= inSample.mStepsAfter; ++step)
            if (step < stepPreempted.size() && stepPreempted[step]) return true;
        return false;
    };
    for (size_t kind = 0; kind < cNumKinds; ++kind)
    {
        std::vector<Sample>& running = ioResult.mKinds[kind].mRunning;
        const auto kept =
            std::stable_partition(running.begin() + std::ptrdiff_t(firstRunning[kind]), running.end(),
                                  [&](const Sample& inSample) { return !overlapsPreempted(inSample); });
        ioResult.mKinds[kind].mDroppedPreempted += uint64_t(running.end() - kept);
        std::vector<Sample>& dropped = ioResult.mKinds[kind].mRunningInPreemptedSteps;
        dropped.insert(dropped.end(), kept, running.end());
        running.erase(kept, running.end());
    }
}

struct Figures
{
    tools::TimingSummary mWall, mCpu;
    size_t mWaited = 0, mPreempted = 0;
};

Figures Summarize(const std::vector<Sample>& inSamples)
{
    std::vector<double> wall, cpu;
    Figures figures;
    for (const Sample& sample : inSamples)
    {
        wall.push_back(sample.mWallUs);
        cpu.push_back(sample.mCpuUs);
        figures.mWaited += sample.mWaited ? 1 : 0;
        figures.mPreempted += sample.mPreempted ? 1 : 0;
    }
    figures.mWall = tools::Summarize(std::move(wall));
    figures.mCpu = tools::Summarize(std::move(cpu));
    return figures;
}

/// ", " between the names of a list being built.
void Append(std::string& ioList, const std::string& inName)
{
    ioList += std::string(ioList.empty() ? "" : ", ") + inName;
}

/// Prints a mode's table, step, tile, checksum and verdict lines.
void Print(const char* inMode, const ModeResult& inResult, const std::vector<Kind>& inKinds)
{
    bool ratiosMet = true, noErrors = true;
    double worstRatio = 0.0;
    const char* worstKind = "none";
    uint64_t queries = 0, queriesWaited = 0, droppedMixed = 0, droppedPreempted = 0, errors = 0;
    std::string overTarget, waitedKinds, checksum, write;
    for (Kind kind : inKinds)
    {
        const KindResult& result = inResult.mKinds[size_t(kind)];
        const Figures running = Summarize(result.mRunning), idle = Summarize(result.mIdle);
        const double ratio = idle.mWall.mP99 > 0.0 ? running.mWall.mP99 / idle.mWall.mP99 : 0.0;
        // The running samples dropped for a preempted step, put back: what the verdict would read with them
        std::vector<Sample> allRunning = result.mRunning;
        allRunning.insert(allRunning.end(), result.mRunningInPreemptedSteps.begin(),
                          result.mRunningInPreemptedSteps.end());
        const Figures withDropped = Summarize(allRunning);
        std::printf(
            "query_latency %s %s: samples %zu running / %zu idle | running p50 %.1f p99 %.1f max %.1f us "
            "| idle p50 %.1f p99 %.1f max %.1f us | p99 running/idle %.2fx | waited %zu running / %zu "
            "idle | on-core p99 %.1f / %.1f us | preempted %zu / %zu | with the %zu running samples of "
            "preempted steps: p99 %.1f us, %.2fx idle\n",
            inMode, cKindNames[size_t(kind)], result.mRunning.size(), result.mIdle.size(), running.mWall.mP50,
            running.mWall.mP99, running.mWall.mMax, idle.mWall.mP50, idle.mWall.mP99, idle.mWall.mMax, ratio,
            running.mWaited, idle.mWaited, running.mCpu.mP99, idle.mCpu.mP99, running.mPreempted,
            idle.mPreempted, result.mRunningInPreemptedSteps.size(), withDropped.mWall.mP99,
            idle.mWall.mP99 > 0.0 ? withDropped.mWall.mP99 / idle.mWall.mP99 : 0.0);
        checksum += std::string(" ") + cKindNames[size_t(kind)] + " " + cKindCounts[size_t(kind)] + " " +
                    std::to_string(result.mCount);
        errors += result.mErrors;
        noErrors = noErrors && result.mErrors == 0;
        droppedMixed += result.mDroppedMixed;
        droppedPreempted += result.mDroppedPreempted;
        if (!IsQuery(kind))
        {
            write = " | write_set_position (no target): waited " + std::to_string(result.mWaited) + " of " +
                    std::to_string(result.mSamples) + ", longest " +
                    std::to_string(int64_t(std::max(running.mWall.mMax, idle.mWall.mMax))) + " us";
            continue;
        }
        // With no sample on either side the ratio means nothing: counted as missed, not as met
        const bool met = !result.mRunning.empty() && !result.mIdle.empty() && ratio <= 2.0;
        if (!met)
            Append(overTarget,
                   std::string(cKindNames[size_t(kind)]) +
                       (result.mRunning.empty() || result.mIdle.empty() ? " (no samples to compare)" : ""));
        ratiosMet = ratiosMet && met;
        if (ratio >= worstRatio)
        {
            worstRatio = ratio;
            worstKind = cKindNames[size_t(kind)];
        }
        queries += result.mSamples;
        queriesWaited += result.mWaited;
        if (result.mWaited > 0) Append(waitedKinds, cKindNames[size_t(kind)]);
    }

    const tools::TimingSummary step = tools::Summarize(inResult.mStepMs);
    std::printf(
        "query_latency %s step: %zu steps of step_pyramid on one thread, mean %.3f ms p99 %.3f ms max "
        "%.3f ms | %.1f s stepping, %.1f s idle | the steps' own lock waits %.3f ms in all | steps whose "
        "thread was preempted %llu\n",
        inMode, inResult.mStepMs.size(), step.mMean, step.mP99, step.mMax, inResult.mRunningSeconds,
        inResult.mIdleSeconds, inResult.mStepLockWaitMs,
        static_cast<unsigned long long>(inResult.mStepsPreempted));
    if (std::find(inKinds.begin(), inKinds.end(), Kind::TileCollect) != inKinds.end())
    {
        std::printf(
            "query_latency %s tile_collect: %llu collections, %llu bodies collected (%.1f a collection, "
            "awake boxes included), %llu triangles; no retries (the collector reads published poses in "
            "both modes: no lock to wait for, nothing to try again)\n",
            inMode, static_cast<unsigned long long>(inResult.mTileCollections),
            static_cast<unsigned long long>(inResult.mTileBodies),
            double(inResult.mTileBodies) / double(std::max<uint64_t>(inResult.mTileCollections, 1)),
            static_cast<unsigned long long>(inResult.mTileTriangles));
        checksum += " tile_collect triangles " + std::to_string(inResult.mTileTriangles);
    }
    std::printf(
        "query_latency %s checksum:%s | errors %llu | samples dropped: mixed %llu, in a preempted step "
        "%llu\n",
        inMode, checksum.c_str(), static_cast<unsigned long long>(errors),
        static_cast<unsigned long long>(droppedMixed), static_cast<unsigned long long>(droppedPreempted));

    const bool noWaits = queriesWaited == 0;
    if (queries == 0) // --only write_set_position: the targets are on queries
    {
        std::printf("query_latency %s verdict: n/a (no query kind run)%s%s\n", inMode,
                    noErrors ? "" : " | ERRORS", write.c_str());
        return;
    }
    const bool pass = ratiosMet && noWaits && noErrors;
    std::printf("query_latency %s verdict: %s | p99 running <= 2x idle for every query kind: %s (worst %s "
                "%.2fx%s%s) | no query waited for a lock: %s (%llu of %llu waited%s%s)%s%s\n",
                inMode, pass ? "PASS" : "FAIL", ratiosMet ? "met" : "missed", worstKind, worstRatio,
                overTarget.empty() ? "" : "; missed by ", overTarget.c_str(), noWaits ? "met" : "missed",
                static_cast<unsigned long long>(queriesWaited), static_cast<unsigned long long>(queries),
                waitedKinds.empty() ? "" : "; in ", waitedKinds.c_str(), noErrors ? "" : " | ERRORS",
                write.c_str());
}

} // namespace

int main(int inArgc, char** inArgv)
{
    Settings settings;
    tools::BenchOptions options;
    options.mRepetitions = 1; // One run of --seconds per mode unless told otherwise: its samples are many
    std::vector<std::string> names(cKindNames.begin(), cKindNames.end());
    if (auto stop = tools::ParseBenchOptions(
            inArgc, inArgv,
            "cairn-bench-query-latency: query and write latency while step_pyramid steps and while it is "
            "idle",
            names, options, false,
            [&](CLI::App& ioApp)
            {
                ioApp
                    .add_option("--seconds", settings.mSeconds, "Seconds per mode and repetition (default 8)")
                    ->check(CLI::Range(1.0, 3600.0));
                ioApp.add_option("--mode", settings.mMode, "published, bodylocks or both (default both)")
                    ->check(CLI::IsMember({"published", "bodylocks", "both"}));
                ioApp
                    .add_option(
                        "--max-wait-us", settings.mMaxWaitMicros,
                        "The random busy wait before each query: 0 to this many microseconds (default 300)")
                    ->check(CLI::Range(0, 100000));
                ioApp
                    .add_option(
                        "--write-interval-us", settings.mWriteIntervalMicros,
                        "The random sleep before each write: 0 to this many microseconds (default 2000)")
                    ->check(CLI::Range(0, 1000000));
            }))
        return *stop;
    std::vector<Kind> kinds;
    for (size_t kind = 0; kind < cNumKinds; ++kind)
        if (options.mOnly.empty() || options.mOnly == cKindNames[kind]) kinds.push_back(Kind(kind));
#ifdef NDEBUG
    const char* buildType = "Release";
#else
    const char* buildType = "Debug (figures not representative)";
#endif
    std::printf(
        "cairn-bench-query-latency: build %s, mode %s, %.1f s a mode x %d repetitions, query wait 0-%d us, "
        "write interval 0-%d us; %s\n",
        buildType, settings.mMode.c_str(), settings.mSeconds, options.mRepetitions, settings.mMaxWaitMicros,
        settings.mWriteIntervalMicros, tools::DescribeMachine().c_str());

    struct Mode
    {
        const char* mName;
        QueryReads mReads;
    };
    for (const Mode& mode :
         {Mode{"published", QueryReads::PublishedPoses}, Mode{"bodylocks", QueryReads::BodyLocks}})
    {
        if (settings.mMode != "both" && settings.mMode != mode.mName) continue;
        ModeResult result;
        for (int rep = 0; rep < options.mRepetitions; ++rep)
            RunOnce(mode.mReads, settings, kinds, 0x5eedull + uint64_t(rep) * 0x100000000ull, result);
        Print(mode.mName, result, kinds);
    }
    return 0;
}
