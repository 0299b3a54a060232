#pragma once

// GameObjects: the game-object update of the demo. Many independent game objects (patrolling kinematic bodies
// around the player) are updated each frame by K jobs on the job system's threads, as a game with a frame
// pipeline does: while the physics step runs on another thread, each object probes the ground (a ray cast
// down), checks its line of sight to the player (a ray cast), looks for bodies around it (a sphere query) and
// walks towards its spot as a character (a CharacterController's Update: a few sweeps and overlaps; it slides
// along props and walls, steps up and follows the terrain) (UpdateQueries); after the step, K jobs move the
// bodies where their characters went (ApplyMoves: broad-phase writes). The queries during the step are the
// load under which the two modes are compared: lock-free (queries read published poses and never wait) and
// global mutex (queries read each body under the one body mutex, which the step holds: the reference engine's
// "before"). The time each thread's jobs spend in queries, and the time they spend blocked on the engine's
// locks (LockWaits, read around each job), are kept apart for the queries and the moves.
//
// Threads: UpdateQueries and ApplyMoves on the main thread, which runs the jobs and waits for them; each
// object is touched by one job only. The per-thread figures are atomics added once per job.

#include "cairn/jobs/JobSystem.h"
#include "cairn/physics/LockWaits.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/character/CharacterController.h"

#include <array>
#include <atomic>
#include <optional>
#include <random>
#include <vector>

namespace cairn::demo
{
using namespace cairn::physics;

class WorldGenerator;

class GameObjects
{
public:
    static constexpr uint32_t cMaxThreadSlots = 16;

    /// inPlayerSpeed (m/s): how fast the place the objects patrol round moves, which they walk to keep up
    /// with
    GameObjects(PhysicsSystem& ioPhysics, const WorldGenerator& inGenerator, uint32_t inCount,
                uint64_t inSeed, float inPlayerSpeed);
    ~GameObjects();

    /// One frame's queries: inJobs jobs on ioJobs look around every object near inPlayer and choose where it
    /// goes; meant to run while the physics step does.
    void UpdateQueries(jobs::JobSystem& ioJobs, uint32_t inJobs, const Vec3& inPlayer, float inDeltaTime);
    /// One frame's moves, after the step: inJobs jobs on ioJobs move every object's body where its queries
    /// chose.
    void ApplyMoves(jobs::JobSystem& ioJobs, uint32_t inJobs);

    uint64_t GetNumQueries() const;
    /// Queries that returned an error (bad input or a wrong thread: a bug in the demo); 0 in a good run.
    uint64_t GetNumQueryErrors() const { return mQueryErrors.load(std::memory_order_relaxed); }
    /// Frames an object walked as a character, and times one was put back at its spot having fallen behind
    /// (its first placement not counted): a game object that mostly walks, not one carried by the demo.
    uint64_t GetNumWalks() const { return mWalks.load(std::memory_order_relaxed); }
    uint64_t GetNumPutBack() const { return mPutBack.load(std::memory_order_relaxed); }
    /// Mean microseconds per query on each thread that ran game-object jobs (in the order threads first
    /// came).
    std::vector<double> GetQueryMicrosPerThread() const;
    double GetQueryMicrosMean() const;
    /// Microseconds per frame that each thread's query jobs spent waiting for the engine's locks of inKind
    /// (LockWaits), in the order of GetQueryMicrosPerThread.
    std::vector<double> GetLockWaitMicrosPerThreadFrame(LockKind inKind) const;
    /// The same for the move jobs, all lock kinds together (their own threads' order).
    std::vector<double> GetMoveLockWaitMicrosPerThreadFrame() const;
    /// Nanoseconds all query jobs have waited for the engine's locks so far (take differences).
    uint64_t GetLockWaitNanosTotal() const;

private:
    struct Object
    {
        BodyID mBody;
        Vec3 mOffset; ///< From the player: the objects move with the streaming window
        float mPhase; ///< Of its patrol circle
        bool mCanSeePlayer = false;
        float mGroundY = 0.0f;
        Vec3 mTarget = Vec3::Zero(); ///< Where its queries sent it this frame (the body's origin)
        bool mPlaced = false;        ///< mTarget holds where it stands (from its first frame on)
        /// Walks it (its filter leaves out the object's own body); empty when its creation failed
        std::optional<CharacterController> mCharacter;
    };
    struct alignas(64) ThreadSlot
    {
        std::atomic<uint64_t> mNanos{0};
        std::atomic<uint64_t> mQueries{0};
        std::array<std::atomic<uint64_t>, cNumLockKinds> mWaitNanos{}; ///< Queries', indexed by LockKind
        std::atomic<uint64_t> mMoves{0};
        std::atomic<uint64_t> mMoveWaitNanos{0}; ///< Moves', all lock kinds
    };

    void QueryObject(Object& ioObject, const Vec3& inPlayer, float inDeltaTime, uint64_t& ioNanos,
                     uint64_t& ioQueries);
    static uint32_t ThreadSlotIndex();

    PhysicsSystem& mPhysics;
    const WorldGenerator& mGenerator;
    std::vector<Object> mObjects;
    const float mMaxWalkSpeed; ///< m/s
    const ShapeRef mWalker;    ///< Every object's character shape: a capsule as tall and wide as its body
    float mTime = 0.0f;
    uint64_t mFrames = 0; ///< Updates with objects (main thread)
    std::array<ThreadSlot, cMaxThreadSlots> mSlots;
    std::atomic<uint64_t> mQueryErrors{0}; ///< Any job thread; relaxed: a count read after the frame's jobs
    std::atomic<uint64_t> mWalks{0};       ///< As mQueryErrors
    std::atomic<uint64_t> mPutBack{0};     ///< As mQueryErrors
};

} // namespace cairn::demo
