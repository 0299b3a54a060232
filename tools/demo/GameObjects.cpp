#include "GameObjects.h"

#include "WorldGenerator.h"
#include "cairn/physics/LockWaits.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/CapsuleShape.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace cairn::demo
{
using namespace cairn::physics;

namespace
{
using Clock = std::chrono::steady_clock;
/// The character: a capsule as tall (1.8 m) and as wide as the object's box
constexpr float cWalkerRadius = 0.3f, cWalkerHalfHeight = 0.6f;
/// The object's box's centre above the ground: its character's capsule's, which keeps its padding clear of
/// the ground, is that padding higher
constexpr float cBodyCentreHeight = 0.9f;
/// How much faster than the player an object may walk after its spot (m/s): its spot circles at 1.5 m/s
/// round a place that follows the player, and an object held at a wall catches up
constexpr float cWalkSpeedOverPlayer = 10.0f;
/// An object left farther than this behind its spot (held at a wall while the player walked on, or left
/// without ground when a tile streamed out under it) is put back at its spot, as a game brings back a
/// companion that fell behind
constexpr float cMaxWalkBehind = 3.0f;
const Vec3 cGravity(0.0f, -9.81f, 0.0f);
std::atomic<uint32_t> sNextThreadSlot{0}; // Relaxed: only uniqueness matters
} // namespace

uint32_t GameObjects::ThreadSlotIndex()
{
    thread_local const uint32_t slot = sNextThreadSlot.fetch_add(1, std::memory_order_relaxed);
    return slot % cMaxThreadSlots;
}

GameObjects::GameObjects(PhysicsSystem& ioPhysics, const WorldGenerator& inGenerator, uint32_t inCount,
                         uint64_t inSeed, float inPlayerSpeed)
    : mPhysics(ioPhysics), mGenerator(inGenerator), mMaxWalkSpeed(inPlayerSpeed + cWalkSpeedOverPlayer),
      mWalker(CapsuleShape::Create(cWalkerHalfHeight, cWalkerRadius).Value())
{
    std::mt19937_64 random(inSeed);
    std::uniform_real_distribution<float> offset(-40.0f, 40.0f), phase(0.0f, 6.28f);
    const ShapeRef shape = BoxShape::Create(Vec3(0.3f, 0.9f, 0.3f)).Value();
    for (uint32_t i = 0; i < inCount; ++i)
    {
        Object object;
        object.mOffset = Vec3(offset(random), 0.0f, offset(random));
        object.mPhase = phase(random);
        BodyCreationSettings settings;
        settings.mShape = shape;
        settings.mPosition = Vec3(object.mOffset.x(), 50.0f, object.mOffset.z());
        settings.mMotionType = MotionType::Kinematic;
        settings.mObjectLayer = Layers::cMoving;
        Result<BodyID> id = mPhysics.GetBodyInterface().CreateAndAddBody(settings, Activation::DontActivate);
        if (!id) continue;
        object.mBody = id.Value();
        CharacterSettings walker;
        walker.mShape = mWalker;
        walker.mFilter.mIgnoreBody = object.mBody;
        Result<CharacterController> character =
            CharacterController::Create(mPhysics, walker, settings.mPosition);
        if (character) object.mCharacter.emplace(std::move(character).Value());
        mObjects.push_back(std::move(object));
    }
}

GameObjects::~GameObjects()
{
    for (const Object& object : mObjects)
    {
        (void)mPhysics.GetBodyInterface().RemoveBody(object.mBody);
        (void)mPhysics.GetBodyInterface().DestroyBody(object.mBody);
    }
}

void GameObjects::QueryObject(Object& ioObject, const Vec3& inPlayer, float inDeltaTime, uint64_t& ioNanos,
                              uint64_t& ioQueries)
{
    const WorldQuery& query = mPhysics.GetWorldQuery();
    // A patrol circle around its spot near the player
    const Vec3 spot = inPlayer + ioObject.mOffset +
                      3.0f * Vec3(std::cos(mTime + ioObject.mPhase), 0.0f, std::sin(mTime + ioObject.mPhase));
    QueryFilter filter;
    filter.mIgnoreBody = ioObject.mBody;

    // Ground probe: straight down from well above the terrain
    const Clock::time_point start = Clock::now();
    RayCast down;
    down.mOrigin = Vec3(spot.x(), mGenerator.GetTerrainHeight(spot.x(), spot.z()) + 30.0f, spot.z());
    down.mDirection = Vec3(0.0f, -60.0f, 0.0f);
    const Result<std::optional<RayCastResult>> ground = query.CastRayClosest(down, filter);
    const bool groundHit = ground.IsOk() && ground.Value().has_value();
    ioObject.mGroundY =
        groundHit ? down.mOrigin.y() + ground.Value()->mFraction * down.mDirection.y() : spot.y();
    // Line of sight to the player's head
    const Vec3 eye(spot.x(), ioObject.mGroundY + 1.6f, spot.z());
    RayCast sight;
    sight.mOrigin = eye;
    sight.mDirection = inPlayer + Vec3(0.0f, 1.6f, 0.0f) - eye;
    const Result<bool> blocked = query.CastRayAny(sight, filter);
    ioObject.mCanSeePlayer = blocked.IsOk() && !blocked.Value();
    // What is around it
    thread_local std::vector<BodyID> around;
    const Status aroundStatus = query.CollideSphere(eye, 2.0f, around, filter);
    int errors = int(!ground.IsOk()) + int(!blocked.IsOk()) + int(!aroundStatus.IsOk());
    ioQueries += 3;
    // It walks to its spot as a character: props and walls stop it, slopes and steps take it up and down
    const Vec3 spotOnGround(spot.x(), ioObject.mGroundY + cBodyCentreHeight, spot.z());
    Vec3 goTo = spotOnGround;
    if (ioObject.mCharacter)
    {
        CharacterController& character = *ioObject.mCharacter;
        const Vec3 behind = spotOnGround - character.GetPosition();
        if (!ioObject.mPlaced || behind.squaredNorm() > cMaxWalkBehind * cMaxWalkBehind)
        {
            errors += int(
                !character.SetPosition(spotOnGround + Vec3(0.0f, character.GetSettings().mPadding, 0.0f)));
            errors += int(!character.SetLinearVelocity(Vec3::Zero())); // Not still falling where it is put
            // Relaxed: a count read after the frame's jobs
            if (ioObject.mPlaced) mPutBack.fetch_add(1, std::memory_order_relaxed);
        }
        else if (inDeltaTime > 0.0f)
        {
            mWalks.fetch_add(1, std::memory_order_relaxed); // Relaxed: as mPutBack
            Vec3 walk(behind.x(), 0.0f, behind.z());
            walk /= inDeltaTime;
            if (walk.norm() > mMaxWalkSpeed) walk *= mMaxWalkSpeed / walk.norm();
            walk.y() = character.GetLinearVelocity().y();
            const Status set = character.SetLinearVelocity(walk);
            const Status updated = set ? character.Update(inDeltaTime, cGravity) : set;
            errors += int(!updated);
            ++ioQueries;
        }
        goTo = character.GetPosition();
    }
    if (errors > 0) mQueryErrors.fetch_add(uint64_t(errors), std::memory_order_relaxed); // A count only
    ioNanos += uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start).count());
    ioObject.mTarget = goTo;
    ioObject.mPlaced = true;
}

void GameObjects::UpdateQueries(jobs::JobSystem& ioJobs, uint32_t inJobs, const Vec3& inPlayer,
                                float inDeltaTime)
{
    mTime += inDeltaTime * 0.5f;
    const uint32_t count = uint32_t(mObjects.size());
    if (count == 0) return;
    ++mFrames;
    const uint32_t grain = std::max(1u, (count + inJobs - 1) / std::max(1u, inJobs));
    ioJobs.ParallelFor(count, grain,
                       [&](uint32_t inBegin, uint32_t inEnd)
                       {
                           uint64_t nanos = 0, queries = 0;
                           uint64_t waitedBefore[cNumLockKinds];
                           for (size_t kind = 0; kind < cNumLockKinds; ++kind)
                               waitedBefore[kind] = GetThisThreadLockWaitNanoseconds(LockKind(kind));
                           for (uint32_t i = inBegin; i < inEnd; ++i)
                               QueryObject(mObjects[i], inPlayer, inDeltaTime, nanos, queries);
                           ThreadSlot& slot = mSlots[ThreadSlotIndex()];
                           // Relaxed: totals read after the jobs are waited for (the wait orders them)
                           slot.mNanos.fetch_add(nanos, std::memory_order_relaxed);
                           slot.mQueries.fetch_add(queries, std::memory_order_relaxed);
                           for (size_t kind = 0; kind < cNumLockKinds; ++kind)
                               slot.mWaitNanos[kind].fetch_add(
                                   GetThisThreadLockWaitNanoseconds(LockKind(kind)) - waitedBefore[kind],
                                   std::memory_order_relaxed);
                       });
}

void GameObjects::ApplyMoves(jobs::JobSystem& ioJobs, uint32_t inJobs)
{
    const uint32_t count = uint32_t(mObjects.size());
    if (count == 0) return;
    // Job j moves objects j, j + jobs, j + 2 jobs...: the objects' bodies have consecutive indices, so jobs
    // running at once lock different body shards (contiguous ranges would walk the shards in lockstep, 128
    // bodies apart being 4 times round the 32 shards, and wait for each other at every body)
    const uint32_t jobCount = std::clamp(inJobs, 1u, count);
    ioJobs.ParallelFor(jobCount, 1,
                       [&](uint32_t inBegin, uint32_t inEnd)
                       {
                           const uint64_t waitedBefore = GetThisThreadLockWaitNanoseconds();
                           uint64_t moves = 0;
                           for (uint32_t job = inBegin; job < inEnd; ++job)
                               for (uint32_t i = job; i < count; i += jobCount, ++moves)
                                   // A broad-phase write from this thread
                                   (void)mPhysics.GetBodyInterface().SetPosition(
                                       mObjects[i].mBody, mObjects[i].mTarget, Activation::DontActivate);
                           ThreadSlot& slot = mSlots[ThreadSlotIndex()];
                           // Relaxed: totals read after the jobs are waited for (the wait orders them)
                           slot.mMoves.fetch_add(moves, std::memory_order_relaxed);
                           slot.mMoveWaitNanos.fetch_add(GetThisThreadLockWaitNanoseconds() - waitedBefore,
                                                         std::memory_order_relaxed);
                       });
}

uint64_t GameObjects::GetNumQueries() const
{
    uint64_t total = 0;
    for (const ThreadSlot& slot : mSlots)
        total += slot.mQueries.load(std::memory_order_relaxed);
    return total;
}

std::vector<double> GameObjects::GetQueryMicrosPerThread() const
{
    std::vector<double> perThread;
    for (const ThreadSlot& slot : mSlots)
    {
        const uint64_t queries = slot.mQueries.load(std::memory_order_relaxed);
        if (queries > 0)
            perThread.push_back(double(slot.mNanos.load(std::memory_order_relaxed)) / 1000.0 /
                                double(queries));
    }
    return perThread;
}

std::vector<double> GameObjects::GetLockWaitMicrosPerThreadFrame(LockKind inKind) const
{
    std::vector<double> perThread;
    for (const ThreadSlot& slot : mSlots)
        if (slot.mQueries.load(std::memory_order_relaxed) > 0) // The threads of GetQueryMicrosPerThread
            perThread.push_back(double(slot.mWaitNanos[size_t(inKind)].load(std::memory_order_relaxed)) /
                                1000.0 / double(std::max<uint64_t>(1, mFrames)));
    return perThread;
}

std::vector<double> GameObjects::GetMoveLockWaitMicrosPerThreadFrame() const
{
    std::vector<double> perThread;
    for (const ThreadSlot& slot : mSlots)
        if (slot.mMoves.load(std::memory_order_relaxed) > 0)
            perThread.push_back(double(slot.mMoveWaitNanos.load(std::memory_order_relaxed)) / 1000.0 /
                                double(std::max<uint64_t>(1, mFrames)));
    return perThread;
}

uint64_t GameObjects::GetLockWaitNanosTotal() const
{
    uint64_t total = 0;
    for (const ThreadSlot& slot : mSlots)
        for (const std::atomic<uint64_t>& waited : slot.mWaitNanos)
            total += waited.load(std::memory_order_relaxed);
    return total;
}

double GameObjects::GetQueryMicrosMean() const
{
    uint64_t nanos = 0, queries = 0;
    for (const ThreadSlot& slot : mSlots)
    {
        nanos += slot.mNanos.load(std::memory_order_relaxed);
        queries += slot.mQueries.load(std::memory_order_relaxed);
    }
    return queries == 0 ? 0.0 : double(nanos) / 1000.0 / double(queries);
}

} // namespace cairn::demo
