#pragma once

// Guards: characters along the player's path that go limp when a ball hits them. A standing guard is one
// kinematic capsule on the path ahead of the player (a game's character controller; the path's corridor is
// kept clear of props), and the player shoots at it 6-14 m before it reaches it. When a ball comes within
// reach of the capsule, the capsule gives way to a humanoid ragdoll in the same place (HumanoidRagdoll.h: 23
// parts and 22 swing-twist joints), its bodies added as one broad-phase batch (Ragdoll::Create), pushed the
// way the ball flew; it falls limp and its joints' limits and friction settle it. At rest its parts are
// sleeping dynamic bodies: navmesh obstacles, whose tiles are rebuilt around them. A limp guard is taken away
// after cLimpSeconds or once the player is 60 m past it, and a new one stands ahead.
//
// Threads: the main thread only, outside the physics step (it owns everything here).

#include "DemoResult.h"
#include "Projectiles.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/ragdoll/Ragdoll.h"

#include <optional>
#include <vector>

namespace cairn::demo
{
using namespace cairn::physics;

class WorldGenerator;

class Guards
{
public:
    static constexpr int cNumGuards = 4;         ///< Standing or limp at once
    static constexpr float cLimpSeconds = 12.0f; ///< A limp guard is taken away after this
    static constexpr float cHeight = 1.8f;       ///< m

    Guards(PhysicsSystem& ioPhysics, const WorldGenerator& inGenerator);
    ~Guards() { RemoveAll(); }
    Guards(const Guards&) = delete;
    Guards& operator=(const Guards&) = delete;

    /// Before the step of frame inFrame (at inSeconds): guards placed ahead where one is missing, shots at
    /// those in range (when inShoot), limp ones taken away.
    void Update(int inFrame, float inSeconds, const Vec3& inPlayer, Projectiles& ioProjectiles, bool inShoot);
    /// After the step: guards a ball reached go limp; limp ones that came to rest are counted.
    void AfterStep(int inFrame, const Projectiles& inProjectiles);
    void RemoveAll();

    const GuardStats& GetStats() const { return mStats; }
    /// The bodies of the guards gone limp and not yet taken away (for checks).
    void GetLimpBodies(std::vector<BodyID>& outBodies) const;

private:
    struct Guard
    {
        BodyID mCapsule;                 ///< While standing
        std::optional<Ragdoll> mRagdoll; ///< Once limp
        Vec3 mFeet = Vec3::Zero();
        Quat mFacing = Quat::Identity();
        float mPathTime = 0.0f; ///< When the player passes it: its place is the player's path then, aside
        int mShotFrame = -1;
        int mLimpFrame = -1;
        bool mRested = false;
    };

    /// A guard standing on the player's path at inPathTime, beside it.
    void Place(Guard& ioGuard, float inPathTime, int inSide);
    void Remove(Guard& ioGuard);
    void GoLimp(Guard& ioGuard, int inFrame, const Vec3& inBallVelocity);

    PhysicsSystem& mPhysics;
    const WorldGenerator& mGenerator;
    RagdollSettings mRagdoll; ///< The humanoid, made once
    ShapeRef mCapsule;
    std::vector<Guard> mGuards;
    float mNextPathTime = 0.0f; ///< Of the next guard placed
    uint32_t mNextGroup = 1;    ///< Each ragdoll's collision group
    int mNextSide = 1;
    std::vector<BodyID> mBalls; ///< Scratch
    GuardStats mStats;
};

} // namespace cairn::demo
