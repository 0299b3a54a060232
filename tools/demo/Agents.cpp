#include "Agents.h"

#include <chrono>

namespace cairn::demo
{

namespace
{
constexpr float cSpeed = 3.0f;          ///< m/s
constexpr float cInvokerRadius = 20.0f; ///< m of navmesh each agent asks for
constexpr float cTargetRange = 15.0f;   ///< Targets within this of the player
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
        mScheduler.RemoveInvoker(agent.mInvoker);
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
    std::uniform_real_distribution<float> offset(-cTargetRange, cTargetRange);
    const float x = inPlayer.x() + offset(mRandom), z = inPlayer.z() + offset(mRandom);
    const Vec3 target(x, mGenerator.GetTerrainHeight(x, z), z);
    const auto start = std::chrono::steady_clock::now();
    Result<navmesh::PathResult> path = mNavMesh.FindPath(ioAgent.mPosition, target);
    mStats.mPathMicros +=
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
    ++mStats.mPathQueries;
    ioAgent.mPath.clear();
    ioAgent.mNext = 0;
    ioAgent.mRepathIn = 2.0f;
    if (!path)
    {
        // The navmesh there is not built yet, or the agent stands where it has none: back to the player's
        // path, which is kept clear, and try again soon
        if (path.GetError().mMessage.find("start") != std::string::npos)
            ioAgent.mPosition =
                Vec3(inPlayer.x(), mGenerator.GetTerrainHeight(inPlayer.x(), inPlayer.z()), inPlayer.z());
        return;
    }
    if (path.Value().mReachedEnd) ++mStats.mPathsFound;
    ioAgent.mPath = path.Value().mStraightPath;
    if (GoesThroughWall(ioAgent.mPath)) ++mStats.mPathsThroughWalls;
}

void Agents::Update(float inDeltaTime, const Vec3& inPlayer)
{
    for (Agent& agent : mAgents)
    {
        agent.mRepathIn -= inDeltaTime;
        if (agent.mNext >= agent.mPath.size() || agent.mRepathIn <= 0.0f) Repath(agent, inPlayer);
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
        if ((agent.mPosition - inPlayer).norm() > 60.0f)
        {
            agent.mPosition =
                Vec3(inPlayer.x(), mGenerator.GetTerrainHeight(inPlayer.x(), inPlayer.z()), inPlayer.z());
            agent.mPath.clear();
        }
        mScheduler.MoveInvoker(agent.mInvoker, agent.mPosition);
    }
}

} // namespace cairn::demo
