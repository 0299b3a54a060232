#include "Agents.h"

#include <chrono>

namespace cairn::demo
{
using namespace cairn::physics;

namespace
{
constexpr float cSpeed = 3.0f;           ///< m/s
constexpr float cInvokerRadius = 20.0f;  ///< m of navmesh each agent asks for
constexpr float cWanderRadius = 15.0f;   ///< Goals within this of the agent, reachable from where it stands
constexpr float cFollowDistance = 25.0f; ///< Further from the player, the agent heads for the player
/// How far the player's way a follower heads while the player's tiles are not built (inside its own navmesh)
constexpr float cFollowStep = 15.0f;
constexpr float cCatchUpDistance = 60.0f;    ///< An agent this far behind is put back beside the player
constexpr float cRetrySeconds = 0.25f;       ///< Wait before asking again when there was no navmesh to ask
constexpr float cPartialRetrySeconds = 0.5f; ///< ... and after a path that ended short of its goal
} // namespace

Agents::Agents(PhysicsSystem& ioPhysics, const WorldGenerator& inGenerator, const TileStreamer& inStreamer,
               navmesh::NavMeshWorld& ioNavMesh, navmesh::TileScheduler& ioScheduler, int inCount,
               uint64_t inSeed)
    : mPhysics(ioPhysics), mGenerator(inGenerator), mStreamer(inStreamer), mNavMesh(ioNavMesh),
      mScheduler(ioScheduler), mRandom(inSeed)
{
    // On the player's path, which the world keeps clear of props
    std::uniform_real_distribution<float> when(0.0f, 2.0f);
    for (int i = 0; i < inCount; ++i)
    {
        Agent agent;
        agent.mPosition = mGenerator.GetPlayerPosition(when(mRandom));
        // The agents start on the generated terrain, inside the world: an error here is a bug in the demo
        agent.mInvoker = mScheduler.AddInvoker(agent.mPosition, cInvokerRadius).Value();
        mAgents.push_back(agent);
    }
}

Agents::~Agents()
{
    for (const Agent& agent : mAgents)
        (void)mScheduler.RemoveInvoker(agent.mInvoker); // Its own, added once: it can not be unknown
}

Vec3 Agents::OnGround(const Vec3& inPoint) const
{
    return Vec3(inPoint.x(), mGenerator.GetTerrainHeight(inPoint.x(), inPoint.z()), inPoint.z());
}

bool Agents::GoesThroughWall(const std::vector<Vec3>& inPath) const
{
    QueryFilter filter;
    filter.mObjectLayers = ObjectLayerMask(1) << Layers::cStatic;
    std::vector<BodyID> hits;
    for (size_t i = 0; i + 1 < inPath.size(); ++i)
    {
        const Vec3 a = inPath[i], b = inPath[i + 1];
        const int samples = std::max(1, int((b - a).norm() / 0.25f));
        for (int s = 0; s <= samples; ++s)
        {
            const Vec3 p = a + (b - a) * (float(s) / float(samples)) + Vec3(0.0f, 1.2f, 0.0f);
            // A path that cannot be checked is not known to be clear: it counts against the invariant
            if (!mPhysics.GetWorldQuery().CollideSphere(p, 0.2f, hits, filter)) return true;
            for (const BodyID& hit : hits)
                if (!mStreamer.IsTerrain(hit)) return true;
        }
    }
    return false;
}

void Agents::Repath(Agent& ioAgent, const Vec3& inPlayer)
{
    ioAgent.mPath.clear();
    ioAgent.mNext = 0;
    ioAgent.mRepathIn = cRetrySeconds;
    const auto start = std::chrono::steady_clock::now();
    // The goal is a navmesh point, as a game's AI picks one: a random point reachable from the agent, or,
    // when it has fallen behind, the navmesh under the player (or its way: FollowGoal). A random point on the
    // terrain was inside a prop or on an unreachable roof most of the time
    const float toPlayer =
        (Vec3(inPlayer.x(), 0, inPlayer.z()) - Vec3(ioAgent.mPosition.x(), 0, ioAgent.mPosition.z())).norm();
    Result<Vec3> goal =
        toPlayer > cFollowDistance
            ? FollowGoal(mNavMesh, ioAgent.mPosition, inPlayer, cFollowStep,
                         [&](float inX, float inZ) { return mGenerator.GetTerrainHeight(inX, inZ); })
            : mNavMesh.FindRandomPointAround(ioAgent.mPosition, cWanderRadius, mRandom());
    Result<navmesh::PathResult> path = goal ? mNavMesh.FindPath(ioAgent.mPosition, goal.Value())
                                            : Result<navmesh::PathResult>(goal.GetError());
    mStats.mPathMicros +=
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
    ++mStats.mPathQueries;
    if (!path)
    {
        // No navmesh under the agent or the goal yet (its tiles are still being built). An agent that stands
        // where there is none goes back to the player's path, which is kept clear
        ++mStats.mPathsFailed;
        if (!mNavMesh.FindNearestPoint(ioAgent.mPosition)) ioAgent.mPosition = OnGround(inPlayer);
        return;
    }
    ++(path.Value().mReachedEnd ? mStats.mPathsFound : mStats.mPathsPartial);
    ioAgent.mPath = path.Value().mStraightPath;
    ioAgent.mPathReachesGoal = path.Value().mReachedEnd;
    // A partial path ends where the built navmesh does: asking again at once would get the same path
    ioAgent.mRepathIn = path.Value().mReachedEnd ? 2.0f : cPartialRetrySeconds;
    if (GoesThroughWall(ioAgent.mPath)) ++mStats.mPathsThroughWalls;
}

void Agents::Update(float inDeltaTime, const Vec3& inPlayer)
{
    for (Agent& agent : mAgents)
    {
        agent.mRepathIn -= inDeltaTime;
        // Arrived, or time for a fresh path (the navmesh changes); an agent without a path waits for its
        // retry
        if (agent.mRepathIn <= 0.0f ||
            (agent.mPathReachesGoal && !agent.mPath.empty() && agent.mNext >= agent.mPath.size()))
            Repath(agent, inPlayer);
        // Walk along the straight path
        float step = cSpeed * inDeltaTime;
        while (step > 0.0f && agent.mNext < agent.mPath.size())
        {
            const Vec3 toCorner = agent.mPath[agent.mNext] - agent.mPosition;
            const float distance = toCorner.norm();
            if (distance <= step)
            {
                agent.mPosition = agent.mPath[agent.mNext++];
                step -= distance;
                mStats.mDistance += distance;
            }
            else
            {
                agent.mPosition += toCorner * (step / distance);
                mStats.mDistance += step;
                step = 0.0f;
            }
        }
        // An agent left far behind by the player (its navmesh not built yet) catches up
        if ((agent.mPosition - inPlayer).norm() > cCatchUpDistance)
        {
            agent.mPosition = OnGround(inPlayer);
            agent.mPath.clear();
            agent.mRepathIn = 0.0f; // A new goal from where it stands now
            ++mStats.mCatchUps;
        }
        if (Status moved = mScheduler.MoveInvoker(agent.mInvoker, agent.mPosition);
            !moved && mStats.mErrors.size() < 20)
            mStats.mErrors.push_back("agent's navmesh invoker: " + moved.GetError().mMessage);
    }
}

} // namespace cairn::demo
