#include "Projectiles.h"

#include "WorldGenerator.h"
#include "cairn/physics/shapes/SphereShape.h"

#include <cmath>

namespace cairn::demo
{
using namespace cairn::physics;

namespace
{
constexpr int cFramesBetweenThrows = 12; ///< Five a second
constexpr int cLifetimeFrames = 300;     ///< Five seconds
constexpr float cSpeed = 14.0f;          ///< m/s
} // namespace

Projectiles::Projectiles(PhysicsSystem& ioPhysics, const WorldGenerator& inGenerator, uint64_t inSeed)
    : mPhysics(ioPhysics), mGenerator(inGenerator), mRandom(inSeed),
      mShape(SphereShape::Create(cRadius).Value())
{
}

void Projectiles::Update(int inFrame, const Vec3& inPlayer)
{
    BodyInterface& bodies = mPhysics.GetBodyInterface();
    while (!mBalls.empty() && inFrame - mBalls.front().mBornFrame > cLifetimeFrames)
    {
        (void)bodies.RemoveBody(mBalls.front().mBody);
        (void)bodies.DestroyBody(mBalls.front().mBody);
        mBalls.pop_front();
    }
    if (inFrame % cFramesBetweenThrows != 0) return;
    // At a spot 5-25 m away in any direction, in a flat arc
    std::uniform_real_distribution<float> angle(0.0f, 6.2831853f), distance(5.0f, 25.0f);
    const float a = angle(mRandom), d = distance(mRandom);
    const float x = inPlayer.x() + d * std::cos(a), z = inPlayer.z() + d * std::sin(a);
    const Vec3 from = inPlayer + Vec3(0.0f, 2.0f, 0.0f);
    const Vec3 to(x, mGenerator.GetTerrainHeight(x, z) + 0.5f, z);
    Throw(inFrame, from, to, (to - from).norm() / cSpeed);
}

void Projectiles::ThrowAt(int inFrame, const Vec3& inFrom, const Vec3& inTarget)
{
    Throw(inFrame, inFrom, inTarget, cAimedFlightSeconds);
}

void Projectiles::Throw(int inFrame, const Vec3& inFrom, const Vec3& inTo, float inFlight)
{
    if (!(inFlight > 0.0f)) return;
    BodyCreationSettings settings;
    settings.mShape = mShape;
    settings.mPosition = inFrom;
    // Aimed to arrive after the flight time despite gravity
    settings.mLinearVelocity = (inTo - inFrom) / inFlight - 0.5f * inFlight * mPhysics.GetSettings().mGravity;
    settings.mDensity = 3000.0f;
    settings.mObjectLayer = Layers::cMoving;
    settings.mFriction = 0.5f;
    // Fast and small: swept from where each step starts, so a ball never passes through a thin crate or wall
    settings.mMotionQuality = MotionQuality::LinearCast;
    Result<BodyID> id = mPhysics.GetBodyInterface().CreateAndAddBody(settings, Activation::Activate);
    if (!id) return;
    mBalls.push_back({id.Value(), inFrame});
    ++mThrown;
}

void Projectiles::GetBalls(std::vector<BodyID>& outBalls) const
{
    outBalls.clear();
    for (const Ball& ball : mBalls)
        outBalls.push_back(ball.mBody);
}

void Projectiles::RemoveAll()
{
    BodyInterface& bodies = mPhysics.GetBodyInterface();
    for (const Ball& ball : mBalls)
    {
        (void)bodies.RemoveBody(ball.mBody);
        (void)bodies.DestroyBody(ball.mBody);
    }
    mBalls.clear();
}

} // namespace cairn::demo
