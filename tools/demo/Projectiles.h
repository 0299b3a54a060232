#pragma once

// Projectiles: the player throws heavy balls at the world around it, a few a second, so that crates and
// stacks that were streamed in asleep get knocked over and the physics step has steady work, as in a game.
// Balls are removed after a few seconds. Aimed shots (ThrowAt) fly fast and flat, for the guards (Guards.h).
// Threads: the main thread only, between physics steps.

#include "cairn/physics/PhysicsSystem.h"

#include <deque>
#include <random>
#include <vector>

namespace cairn::demo
{
using namespace cairn::physics;

class WorldGenerator;

class Projectiles
{
public:
    Projectiles(PhysicsSystem& ioPhysics, const WorldGenerator& inGenerator, uint64_t inSeed);
    ~Projectiles() { RemoveAll(); }

    /// Frame inFrame: maybe throws a ball from inPlayer, and removes balls older than their lifetime.
    void Update(int inFrame, const Vec3& inPlayer);
    /// Frame inFrame: a ball from inFrom that arrives at inTarget cAimedFlightSeconds later.
    void ThrowAt(int inFrame, const Vec3& inFrom, const Vec3& inTarget);
    void RemoveAll();
    uint32_t GetNumThrown() const { return mThrown; }
    /// The balls in flight or rolling, oldest first.
    void GetBalls(std::vector<BodyID>& outBalls) const;

    static constexpr float cRadius = 0.35f;            ///< m
    static constexpr float cAimedFlightSeconds = 0.5f; ///< An aimed shot's time to its target

private:
    /// A ball from inFrom that arrives at inTo after inFlight seconds (the arc despite gravity).
    void Throw(int inFrame, const Vec3& inFrom, const Vec3& inTo, float inFlight);

    struct Ball
    {
        BodyID mBody;
        int mBornFrame;
    };

    PhysicsSystem& mPhysics;
    const WorldGenerator& mGenerator;
    std::mt19937_64 mRandom;
    ShapeRef mShape;
    std::deque<Ball> mBalls;
    uint32_t mThrown = 0;
};

} // namespace cairn::demo
