// Guards: characters on the player's path that go limp when hit (see Guards.h).

#include "Guards.h"

#include "WorldGenerator.h"
#include "cairn/physics/ragdoll/HumanoidRagdoll.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "common/FrameTimes.h"

#include <chrono>
#include <cmath>
#include <utility>

namespace cairn::demo
{
using namespace cairn::physics;

namespace
{
using Clock = std::chrono::steady_clock;

constexpr float cRadius = 0.3f;     ///< m, the standing capsule's
constexpr float cStance = 0.35f;    ///< m from the middle that the ragdoll's feet and toes reach
constexpr float cSideOffset = 1.2f; ///< m from the path's middle: inside its prop-free corridor
/// Guards stand at least this far ahead of the player when placed, this far apart along its path (m)
constexpr float cPlaceAhead = 20.0f, cPlaceSpacing = 6.0f;
/// The player shoots at a guard this far ahead (m along the path, at the player's speed): near enough that
/// a hill between them seldom takes the ball, far enough to see it fly
constexpr float cShootFrom = 6.0f, cShootTo = 14.0f;
constexpr int cFramesBetweenShots = 45;    ///< At one guard, when a shot missed
constexpr float cLeftBehindSeconds = 1.5f; ///< A standing guard the player passed this long ago goes
/// And a limp one this far behind: streaming takes the ground away from under what the player leaves far
/// behind (m)
constexpr float cLimpLeftBehind = 60.0f;
constexpr float cReach = 0.15f;    ///< m a ball may be off the capsule and still hit it
constexpr float cPushSpeed = 3.0f; ///< m/s: the hit's push on every part, the way the ball flew

/// Distance from inPoint to the segment [inA, inB]
float DistanceToSegment(const Vec3& inPoint, const Vec3& inA, const Vec3& inB)
{
    const Vec3 ab = inB - inA;
    const float t = std::clamp((inPoint - inA).dot(ab) / ab.squaredNorm(), 0.0f, 1.0f);
    return (inPoint - (inA + t * ab)).norm();
}
} // namespace

Guards::Guards(PhysicsSystem& ioPhysics, const WorldGenerator& inGenerator)
    : mPhysics(ioPhysics), mGenerator(inGenerator), mRagdoll(MakeHumanoidRagdoll(cHeight)),
      mCapsule(CapsuleShape::Create(0.5f * cHeight - cRadius, cRadius).Value()), mGuards(cNumGuards)
{
    // A heavy ball slams a hand or a foot into the ground faster than a step's discrete contacts hold:
    // swept, as the balls are, so that no part ends up under the height field
    for (RagdollPart& part : mRagdoll.mParts)
        part.mBody.mMotionQuality = MotionQuality::LinearCast;
}

void Guards::Place(Guard& ioGuard, float inPathTime, int inSide)
{
    const Vec3 here = mGenerator.GetPlayerPosition(inPathTime);
    Vec3 along = mGenerator.GetPlayerPosition(inPathTime + 0.1f) - here;
    along.y() = 0.0f;
    along = along.squaredNorm() > 1e-8f ? along.normalized() : Vec3(1.0f, 0.0f, 0.0f);
    const Vec3 side(-along.z(), 0.0f, along.x());
    Vec3 feet = here + side * (cSideOffset * float(inSide));
    // On the highest ground under its stance: on a slope, a foot started below the height field's surface
    // would be pushed through it, not out
    feet.y() = mGenerator.GetTerrainHeight(feet.x(), feet.z());
    for (const auto& [dx, dz] :
         {std::pair(cStance, 0.0f), {-cStance, 0.0f}, {0.0f, cStance}, {0.0f, -cStance}})
        feet.y() = std::max(feet.y(), mGenerator.GetTerrainHeight(feet.x() + dx, feet.z() + dz));
    feet.y() += 0.02f;
    // Facing the player as it comes: the ragdoll's +z turned to -along
    const float yaw = std::atan2(-along.x(), -along.z());
    ioGuard = Guard();
    ioGuard.mFeet = feet;
    ioGuard.mFacing = Quat(Eigen::AngleAxisf(yaw, Vec3::UnitY()));
    ioGuard.mPathTime = inPathTime;

    BodyCreationSettings capsule;
    capsule.mShape = mCapsule;
    capsule.mPosition = feet + Vec3(0.0f, 0.5f * cHeight, 0.0f);
    capsule.mRotation = ioGuard.mFacing;
    capsule.mMotionType = MotionType::Kinematic;
    capsule.mObjectLayer = Layers::cMoving;
    Result<BodyID> id = mPhysics.GetBodyInterface().CreateAndAddBody(capsule, Activation::DontActivate);
    if (!id)
    {
        if (mStats.mErrors.size() < cMaxStatsErrors)
            mStats.mErrors.push_back("guard: " + id.GetError().mMessage);
        return;
    }
    ioGuard.mCapsule = id.Value();
    ++mStats.mPlaced;
}

void Guards::Remove(Guard& ioGuard)
{
    BodyInterface& bodies = mPhysics.GetBodyInterface();
    if (!ioGuard.mCapsule.IsInvalid())
    {
        (void)bodies.RemoveBody(ioGuard.mCapsule);
        (void)bodies.DestroyBody(ioGuard.mCapsule);
    }
    if (ioGuard.mRagdoll)
    {
        mStats.mRemovedBeforeRest += ioGuard.mRested ? 0 : 1;
        if (Status destroyed = ioGuard.mRagdoll->Destroy(mPhysics);
            !destroyed && mStats.mErrors.size() < cMaxStatsErrors)
            mStats.mErrors.push_back("ragdoll destroy: " + destroyed.GetError().mMessage);
    }
    ioGuard = Guard();
}

void Guards::GetLimpBodies(std::vector<BodyID>& outBodies) const
{
    outBodies.clear();
    for (const Guard& guard : mGuards)
        if (guard.mRagdoll)
            outBodies.insert(outBodies.end(), guard.mRagdoll->GetBodies().begin(),
                             guard.mRagdoll->GetBodies().end());
}

void Guards::RemoveAll()
{
    for (Guard& guard : mGuards)
        Remove(guard);
}

void Guards::Update(int inFrame, float inSeconds, const Vec3& inPlayer, Projectiles& ioProjectiles,
                    bool inShoot)
{
    const int limpFrames = int(cLimpSeconds * 60.0f);
    // Distances along the path as the player's seconds (a player standing still gets guards a metre a second)
    const float speed = std::max(1.0f, std::abs(mGenerator.GetSettings().mPlayerSpeed));
    mNextPathTime = std::max(mNextPathTime, inSeconds + cPlaceAhead / speed);
    for (Guard& guard : mGuards)
    {
        const bool standing = !guard.mCapsule.IsInvalid();
        const bool limp = guard.mRagdoll.has_value();
        const bool passed = guard.mPathTime < inSeconds;
        if ((limp && (inFrame - guard.mLimpFrame > limpFrames ||
                      (passed && (inPlayer - guard.mFeet).norm() > cLimpLeftBehind))) ||
            (standing && guard.mPathTime < inSeconds - cLeftBehindSeconds))
            Remove(guard);
        if (guard.mCapsule.IsInvalid() && !guard.mRagdoll)
        {
            Place(guard, mNextPathTime, mNextSide);
            mNextPathTime += cPlaceSpacing / speed;
            mNextSide = -mNextSide;
            continue;
        }
        const float ahead = (guard.mPathTime - inSeconds) * mGenerator.GetSettings().mPlayerSpeed;
        if (inShoot && !guard.mCapsule.IsInvalid() && ahead >= cShootFrom && ahead <= cShootTo &&
            (guard.mShotFrame < 0 || inFrame - guard.mShotFrame > cFramesBetweenShots))
        {
            ioProjectiles.ThrowAt(inFrame, inPlayer + Vec3(0.0f, 2.0f, 0.0f),
                                  guard.mFeet + Vec3(0.0f, 0.65f * cHeight, 0.0f));
            guard.mShotFrame = inFrame;
            ++mStats.mShots;
        }
    }
}

void Guards::GoLimp(Guard& ioGuard, int inFrame, const Vec3& inBallVelocity)
{
    BodyInterface& bodies = mPhysics.GetBodyInterface();
    (void)bodies.RemoveBody(ioGuard.mCapsule);
    (void)bodies.DestroyBody(ioGuard.mCapsule);
    ioGuard.mCapsule = BodyID();
    const Clock::time_point start = Clock::now();
    Result<Ragdoll> ragdoll = Ragdoll::Create(mPhysics, mRagdoll, ioGuard.mFeet, ioGuard.mFacing,
                                              mNextGroup++, Activation::Activate);
    const double ms = tools::MillisecondsSince(start);
    if (!ragdoll)
    {
        if (mStats.mErrors.size() < cMaxStatsErrors)
            mStats.mErrors.push_back("ragdoll: " + ragdoll.GetError().mMessage);
        return;
    }
    ioGuard.mRagdoll = std::move(ragdoll).Value();
    ioGuard.mLimpFrame = inFrame;
    ++mStats.mHits;
    mStats.mMakeMs.push_back(ms);
    Vec3 push(inBallVelocity.x(), 0.0f, inBallVelocity.z());
    push = push.squaredNorm() > 1e-6f ? Vec3(push.normalized() * cPushSpeed) : Vec3::Zero();
    for (const BodyID& part : ioGuard.mRagdoll->GetBodies())
        (void)bodies.SetLinearVelocity(part, push);
}

void Guards::AfterStep(int inFrame, const Projectiles& inProjectiles)
{
    BodyInterface& bodies = mPhysics.GetBodyInterface();
    inProjectiles.GetBalls(mBalls);
    for (Guard& guard : mGuards)
    {
        if (!guard.mCapsule.IsInvalid())
        {
            const Vec3 low = guard.mFeet + Vec3(0.0f, cRadius, 0.0f);
            const Vec3 high = guard.mFeet + Vec3(0.0f, cHeight - cRadius, 0.0f);
            for (const BodyID& ball : mBalls)
            {
                Result<Vec3> at = bodies.GetPosition(ball);
                if (!at || DistanceToSegment(at.Value(), low, high) > cRadius + Projectiles::cRadius + cReach)
                    continue;
                Result<Vec3> velocity = bodies.GetLinearVelocity(ball);
                GoLimp(guard, inFrame, velocity ? velocity.Value() : Vec3::Zero());
                break;
            }
        }
        else if (guard.mRagdoll && !guard.mRested)
        {
            bool awake = false;
            for (const BodyID& part : guard.mRagdoll->GetBodies())
            {
                Result<bool> active = bodies.IsActive(part);
                awake = awake || !active || active.Value();
            }
            if (awake) continue;
            guard.mRested = true;
            ++mStats.mAtRest;
            mStats.mSecondsToRest.push_back(double(inFrame - guard.mLimpFrame) / 60.0);
        }
    }
}

} // namespace cairn::demo
