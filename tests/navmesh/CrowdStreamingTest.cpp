// A crowd of 500 agents walking a town for 3,000 frames while its navmesh streams (tiles removed and streamed
// back, a quarter's props streamed out and in, crates dropped on the walkways) keeps issue 32's invariants:
// no agent in a static body or off the navmesh for over a second, few overlaps, no corridor through a removed
// polygon, goals reached; and an agent whose tile goes while its path is pending says it is off the navmesh.

#include "NavMeshSceneFixture.h"
#include "TileChanges.h"
#include "cairn/jobs/JobSystem.h"
#include "cairn/navmesh/Crowd.h"

#include <DetourNavMesh.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <optional>
#include <random>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

constexpr int cFrames = 3000;
constexpr float cDeltaTime = 1.0f / 60.0f;
constexpr int cNumAgents = 500;
/// An agent is at its goal within this x-z distance (the crowd stops within its radius, 0.6 m)
constexpr float cAtGoal = 1.0f;
/// A static body only comes where every agent's centre is at least this far (x-z) from its footprint: the
/// agent's radius and a margin, so that a body never lands on an agent (that would be the scenario's fault)
constexpr float cClearOfAgents = 1.2f;
/// Nor on a goal: a goal inside a box is no goal to reach
constexpr float cClearOfGoals = 1.5f;
/// The sphere that finds an agent inside a static body: at chest height, half the agent's radius. Not the
/// whole radius: the navmesh keeps the agent's centre an agent radius from walls only up to Recast's contour
/// simplification (1.3 cells, 0.26 m) and its cut corners, so an agent on the navmesh comes nearer than its
/// radius to a corner (0.49 m here); one more than half its radius inside a body is no such case, and a
/// crowd that let agents off the navmesh surface was caught in hundreds of checks
constexpr float cChestHeight = 1.0f;
constexpr float cBodyCheckRadius = 0.3f;

class CrowdStreamingTest : public NavMeshSceneFixture
{
protected:
    /// The town: ground over 4 x 4 tiles each side of the origin (102 m square), 25 buildings on a 20 m grid
    /// with streets of 11 to 15 m between them, and 56 pillars (the props) on the streets. The buildings are
    /// 1.5 m tall: Recast takes a box as its surfaces, so under a roof 2 m up (the agents' height) the ground
    /// inside a building is navmesh, an island agents were placed on (the static-body check found them)
    void BuildTown()
    {
        mGround = AddStaticBox(Vec3(0, -0.5f, 0), Vec3(51, 0.5f, 51));
        for (int a = 0; a < 5; ++a)
            for (int b = 0; b < 5; ++b)
                AddStaticBox(Vec3(-40.0f + 20.0f * float(a), 0.5f, -40.0f + 20.0f * float(b)),
                             Vec3(2.5f + float((a + 2 * b) % 3), 1.0f, 2.5f + float((2 * a + b) % 3)));
        auto addPillar = [&](float inX, float inZ) {
            mPillars.push_back({AddStaticBox(Vec3(inX, 1.0f, inZ), cPillarHalfExtent), Vec3(inX, 1.0f, inZ)});
        };
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b)
                addPillar(-30.0f + 20.0f * float(a), -30.0f + 20.0f * float(b)); // Crossings
        for (int a = 0; a < 5; ++a)
            for (int b = 0; b < 4; ++b)
            {
                addPillar(-40.0f + 20.0f * float(a), -30.0f + 20.0f * float(b)); // Between two buildings
                addPillar(-30.0f + 20.0f * float(b), -40.0f + 20.0f * float(a));
            }
        MakeNavMesh(4);
        ASSERT_TRUE(RunUntilIdle());
    }

    /// x-z distance from inPoint to the footprint of a box centred at inCentre.
    static float DistanceToFootprint(const Vec3& inPoint, const Vec3& inCentre, const Vec3& inHalfExtent)
    {
        const float dx = std::max(0.0f, std::abs(inPoint.x() - inCentre.x()) - inHalfExtent.x());
        const float dz = std::max(0.0f, std::abs(inPoint.z() - inCentre.z()) - inHalfExtent.z());
        return std::sqrt(dx * dx + dz * dz);
    }

    /// True if no agent and no goal is near the footprint of a box at inCentre: a static body may come there.
    bool IsClear(const Crowd& inCrowd, const Vec3& inCentre, const Vec3& inHalfExtent) const
    {
        for (const Walker& walker : mWalkers)
            if (DistanceToFootprint(inCrowd.GetPosition(walker.mID).Value(), inCentre, inHalfExtent) <
                    cClearOfAgents ||
                DistanceToFootprint(walker.mGoal, inCentre, inHalfExtent) < cClearOfGoals)
                return false;
        return true;
    }

    /// A goal for an agent at inFrom: a navmesh point reachable from it, 5 to 20 m away, and not where a
    /// streamed-out prop is to come back (none after 20 draws: the agent draws again next frame).
    std::optional<Vec3> PickGoal(const Vec3& inFrom)
    {
        for (int attempt = 0; attempt < 20; ++attempt)
        {
            const Result<Vec3> goal = mWorld->FindRandomPointAround(inFrom, 20.0f, mNextSeed++);
            if (!goal || Flat(goal.Value() - inFrom).norm() <= 5.0f) continue;
            bool onProp = false;
            for (const Prop& prop : mPropsOut)
                onProp |= DistanceToFootprint(goal.Value(), prop.mCentre, cPillarHalfExtent) < cClearOfGoals;
            if (!onProp) return goal.Value();
        }
        return std::nullopt;
    }

    /// 500 agents at random places on the streets at least 1.5 m apart, each with a goal.
    void AddWalkers(Crowd& ioCrowd)
    {
        std::mt19937 random(11);
        std::uniform_real_distribution<float> coordinate(-50.0f, 50.0f);
        std::vector<Vec3> starts;
        while (int(starts.size()) < cNumAgents)
        {
            const Vec3 candidate(coordinate(random), 0.0f, coordinate(random));
            // On the navmesh right there, on the ground (not a roof)
            const Result<Vec3> onNavMesh = mWorld->FindNearestPoint(candidate, {}, Vec3(0.1f, 1.0f, 0.1f));
            if (!onNavMesh || std::abs(onNavMesh.Value().y()) > 0.3f) continue;
            bool crowded = false;
            for (const Vec3& other : starts)
                crowded |= Flat(other - onNavMesh.Value()).norm() < 1.5f;
            if (!crowded) starts.push_back(onNavMesh.Value());
        }
        for (const Vec3& start : starts)
        {
            Walker walker;
            walker.mID = ioCrowd.AddAgent(start).Value();
            const std::optional<Vec3> goal = PickGoal(start);
            ASSERT_TRUE(goal.has_value()) << "the streets are one walkable area";
            walker.mGoal = *goal;
            ASSERT_TRUE(ioCrowd.SetTarget(walker.mID, walker.mGoal).IsOk());
            mWalkers.push_back(walker);
        }
    }

    /// Agents whose centres are nearer than their radii less 10 % of the smaller one to another's, this
    /// frame: a grid of cells as wide as two largest radii, each agent against those of the 3 x 3 cells
    /// round it.
    int CountOverlappingAgents(const Crowd& inCrowd)
    {
        const float cell = 1.2f;
        mCells.clear();
        for (size_t i = 0; i < mWalkers.size(); ++i)
        {
            const Vec3 position = inCrowd.GetPosition(mWalkers[i].mID).Value();
            mCells.push_back(
                {CellKey(int32_t(std::floor(position.x() / cell)), int32_t(std::floor(position.z() / cell))),
                 uint32_t(i)});
        }
        std::sort(mCells.begin(), mCells.end());
        int overlapping = 0;
        for (size_t i = 0; i < mWalkers.size(); ++i)
        {
            const Vec3 position = inCrowd.GetPosition(mWalkers[i].mID).Value();
            const float radius = inCrowd.GetRadius(mWalkers[i].mID).Value();
            const int32_t cx = int32_t(std::floor(position.x() / cell)),
                          cz = int32_t(std::floor(position.z() / cell));
            bool overlaps = false;
            for (int32_t dx = -1; dx <= 1 && !overlaps; ++dx)
                for (int32_t dz = -1; dz <= 1 && !overlaps; ++dz)
                {
                    const uint64_t key = CellKey(cx + dx, cz + dz);
                    for (auto it = std::lower_bound(mCells.begin(), mCells.end(),
                                                    std::pair<uint64_t, uint32_t>(key, 0));
                         it != mCells.end() && it->first == key && !overlaps; ++it)
                    {
                        if (it->second == i) continue;
                        const Crowd::AgentID other = mWalkers[it->second].mID;
                        const float otherRadius = inCrowd.GetRadius(other).Value();
                        const float distance = Flat(inCrowd.GetPosition(other).Value() - position).norm();
                        overlaps = radius + otherRadius - distance > 0.1f * std::min(radius, otherRadius);
                    }
                }
            overlapping += overlaps ? 1 : 0;
        }
        return overlapping;
    }

    /// True if every agent's corridor holds only polygons the navmesh has now.
    bool CorridorsAreValid(const Crowd& inCrowd) const
    {
        bool valid = true;
        mWorld->Read(
            [&](const dtNavMesh& inNavMesh)
            {
                for (const Walker& walker : mWalkers)
                {
                    const std::vector<uint64_t> corridor = inCrowd.GetCorridor(walker.mID).Value();
                    for (uint64_t polygon : corridor)
                        valid = valid && inNavMesh.isValidPolyRef(dtPolyRef(polygon));
                }
            });
        return valid;
    }

    /// The tile that the most corridors cross, other than inNot (a tile streamed out just before): the one
    /// whose removal makes the most agents replan.
    TileCoord BusiestTile(const Crowd& inCrowd, const TileCoord& inNot) const
    {
        std::map<TileCoord, int> crossings;
        mWorld->Read(
            [&](const dtNavMesh& inNavMesh)
            {
                for (const Walker& walker : mWalkers)
                {
                    std::vector<TileCoord> tiles;
                    const std::vector<uint64_t> corridor = inCrowd.GetCorridor(walker.mID).Value();
                    for (uint64_t polygon : corridor)
                    {
                        const dtMeshTile* tile = nullptr;
                        const dtPoly* poly = nullptr;
                        if (dtStatusFailed(inNavMesh.getTileAndPolyByRef(dtPolyRef(polygon), &tile, &poly)))
                            continue;
                        const TileCoord coord{tile->header->x, tile->header->y};
                        if (std::find(tiles.begin(), tiles.end(), coord) == tiles.end())
                            tiles.push_back(coord);
                    }
                    for (const TileCoord& coord : tiles)
                        ++crossings[coord];
                }
            });
        TileCoord busiest = inNot;
        int most = -1;
        for (const auto& [coord, count] : crossings)
            if (coord != inNot && count > most)
            {
                busiest = coord;
                most = count;
            }
        return busiest;
    }

    static uint64_t CellKey(int32_t inX, int32_t inZ)
    {
        return uint64_t(uint32_t(inX)) << 32 | uint32_t(inZ);
    }
    static Vec3 Flat(const Vec3& inV) { return Vec3(inV.x(), 0.0f, inV.z()); }

    struct Walker
    {
        Crowd::AgentID mID = 0;
        Vec3 mGoal = Vec3::Zero();
        bool mHasGoal = true;      ///< False while it draws a new one
        int mGoalFrame = 0;        ///< When it was given this goal
        int mRetryFrame = 0;       ///< Not before this frame does it ask again for a goal it could not reach
        bool mFirstGoal = true;    ///< Still on its first goal
        int mOffNavMeshFrames = 0; ///< Consecutive, up to this frame
    };
    struct Prop
    {
        BodyID mBody;
        Vec3 mCentre;
    };
    static inline const Vec3 cPillarHalfExtent = Vec3(0.5f, 1.5f, 0.5f);

    BodyID mGround;
    std::vector<Prop> mPillars;
    std::vector<Prop> mPropsOut; ///< Streamed out, to come back
    std::vector<Walker> mWalkers;
    uint64_t mNextSeed = 1;
    std::vector<std::pair<uint64_t, uint32_t>> mCells; ///< Scratch of CountOverlappingAgents
};

TEST_F(CrowdStreamingTest, FiveHundredAgentsKeepTheInvariantsWhileTilesStreamAndRebuild)
{
    ASSERT_NO_FATAL_FAILURE(BuildTown());
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    ASSERT_NO_FATAL_FAILURE(AddWalkers(*crowd));
    jobs::JobSystem jobSystem(jobs::JobSystem::Settings{2});
    const auto start = std::chrono::steady_clock::now();

    std::mt19937 random(7);
    const float border = float(mWorld->GetProfile().GetBorderCells()) * mWorld->GetProfile().mCellSize;
    TileCoord streamedOut{-100, -100};
    int streamBackAt = -1, tilesStreamed = 0;
    std::vector<std::pair<Prop, int>> crates; // With the frame each came
    int cratesDropped = 0, cratesRefused = 0;
    const Vec3 crateHalfExtent(0.6f, 0.6f, 0.6f); // Not climbable (0.9 m), no navmesh on top
    // The figures the invariants are checked on
    uint64_t agentFrames = 0, overlappingAgentFrames = 0;
    int longestOffNavMesh = 0, offNavMeshChecks = 0, offTheNavMesh = 0, agentsInBodies = 0;
    int longestOffNavMeshFrame = -1, firstOffTheNavMeshFrame = -1;
    Crowd::AgentID longestOffNavMeshAgent = 0, firstOffTheNavMeshAgent = 0, firstMislabelledAgent = 0;
    int mislabelled = 0, firstMislabelledFrame = -1, firstMislabelledState = -1;
    int firstInvalidCorridorFrame = -1, invalidCorridorFrames = 0, firstInBodyFrame = -1;
    int goalsAssigned = cNumAgents, goalsReached = 0, firstGoalsReached = 0, retries = 0;
    // Goals given at least 20 s before the end: a walk takes 5 s alone, 20 s leaves room for jams, replans
    // and tiles away
    const int cLastEarlyGoalFrame = cFrames - 1200;
    int earlyGoals = cNumAgents, earlyGoalsReached = 0, goalsNotDrawn = 0;
    std::vector<BodyID> hits;
    QueryFilter staticOnly;
    staticOnly.mObjectLayers = ObjectLayerMask(1) << Layers::cStatic;
    staticOnly.mIgnoreBody = mGround;

    for (int frame = 0; frame < cFrames; ++frame)
    {
        bool waitForTiles = false;
        // A navmesh tile streamed out: the one the most corridors cross. A game streams out tiles no agent
        // stands on, but 500 agents leave none of the 64 empty: those on it go OffNavMesh and wait, the
        // others replan round it. It is streamed in half a second later and built before the crowd's next
        // Update (waitForTiles), so an agent off the navmesh for over a second is one the crowd did not put
        // back...
        if (frame % 150 == 60)
        {
            streamedOut = BusiestTile(*crowd, streamedOut);
            mWorld->Publish(Changes(NavMeshWorld::Removal(streamedOut)));
            streamBackAt = frame + 30;
            ++tilesStreamed;
        }
        // ...streamed in: built again from the physics world (the tile alone: its bounds less the border its
        // neighbours' builds read)
        if (frame == streamBackAt)
        {
            AABB bounds = mWorld->GetGrid().GetTileBounds(streamedOut);
            bounds.mMin += Vec3(border + 0.1f, 0, border + 0.1f);
            bounds.mMax -= Vec3(border + 0.1f, 0, border + 0.1f);
            mScheduler->MarkDirty(bounds);
            waitForTiles = true;
        }
        // A quarter of the town's props streamed out (the scheduler sees the bodies go and rebuilds the
        // tiles; agents walk where they stood)...
        if (frame == 450)
        {
            for (const Prop& prop : mPillars)
                if (prop.mCentre.x() > 0.0f && prop.mCentre.z() > 0.0f)
                {
                    ASSERT_TRUE(mPhysics->GetBodyInterface().RemoveBody(prop.mBody).IsOk());
                    mPropsOut.push_back(prop);
                }
            std::erase_if(mPillars, [](const Prop& inProp)
                          { return inProp.mCentre.x() > 0.0f && inProp.mCentre.z() > 0.0f; });
        }
        // ...and streamed back in from frame 1,350, each once no agent stands where it comes
        if (frame >= 1350)
        {
            for (const Prop& prop : mPropsOut)
                if (IsClear(*crowd, prop.mCentre, cPillarHalfExtent))
                {
                    ASSERT_TRUE(
                        mPhysics->GetBodyInterface().AddBody(prop.mBody, Activation::DontActivate).IsOk());
                    mPillars.push_back(prop);
                    waitForTiles = true;
                }
            std::erase_if(mPropsOut,
                          [&](const Prop& inProp)
                          {
                              return std::find_if(mPillars.begin(), mPillars.end(),
                                                  [&](const Prop& inIn)
                                                  { return inIn.mBody == inProp.mBody; }) != mPillars.end();
                          });
        }
        // A crate dropped on a walkway 3.5 m ahead of a walking agent (a crate fell, a door closed), taken
        // away 7.5 s later
        if (frame % 90 == 30)
        {
            bool dropped = false;
            for (int attempt = 0; attempt < 20 && !dropped; ++attempt)
            {
                const Walker& walker =
                    mWalkers[std::uniform_int_distribution<size_t>(0, mWalkers.size() - 1)(random)];
                const Vec3 velocity = crowd->GetVelocity(walker.mID).Value();
                if (crowd->GetState(walker.mID).Value() != AgentState::Moving || velocity.norm() < 1.0f)
                    continue;
                const Result<Vec3> spot = mWorld->FindNearestPoint(crowd->GetPosition(walker.mID).Value() +
                                                                       velocity.normalized() * 3.5f,
                                                                   {}, Vec3(0.5f, 1.0f, 0.5f));
                if (!spot || std::abs(spot.Value().y()) > 0.3f) continue;
                const Vec3 centre(spot.Value().x(), crateHalfExtent.y(), spot.Value().z());
                if (!IsClear(*crowd, centre, crateHalfExtent)) continue;
                crates.push_back({{AddStaticBox(centre, crateHalfExtent), centre}, frame});
                dropped = true;
            }
            cratesDropped += dropped ? 1 : 0;
            cratesRefused += dropped ? 0 : 1;
            waitForTiles |= dropped;
        }
        while (!crates.empty() && crates.front().second + 450 <= frame)
        {
            ASSERT_TRUE(mPhysics->GetBodyInterface().RemoveBody(crates.front().first.mBody).IsOk());
            ASSERT_TRUE(mPhysics->GetBodyInterface().DestroyBody(crates.front().first.mBody).IsOk());
            crates.erase(crates.begin());
        }

        Frame(); // Physics and the tile scheduler: tiles rebuilt in the background are published here
        // A body added where the navmesh still walks (or a tile streamed in) waits for its tiles before the
        // crowd moves: the crowd keeps agents out of what the navmesh knows, and the background build's
        // latency (longer under the sanitizers) is the scheduler's, not the crowd's, to answer for
        if (waitForTiles)
        {
            ASSERT_TRUE(RunUntilIdle());
        }
        ASSERT_TRUE(crowd->Update(cDeltaTime, &jobSystem).IsOk());

        // No corridor through a polygon that is gone, after every Update
        if (!CorridorsAreValid(*crowd))
        {
            ++invalidCorridorFrames;
            if (firstInvalidCorridorFrame < 0) firstInvalidCorridorFrame = frame;
        }
        overlappingAgentFrames += uint64_t(CountOverlappingAgents(*crowd));
        agentFrames += mWalkers.size();
        for (Walker& walker : mWalkers)
        {
            const Vec3 position = crowd->GetPosition(walker.mID).Value();
            const AgentState state = crowd->GetState(walker.mID).Value();
            // Off the navmesh: no polygon under it, whatever its state says (see below)
            const bool noPolygon = crowd->GetCorridor(walker.mID).Value().empty();
            const bool offNavMesh = noPolygon || state == AgentState::OffNavMesh;
            walker.mOffNavMeshFrames = offNavMesh ? walker.mOffNavMeshFrames + 1 : 0;
            if (walker.mOffNavMeshFrames > longestOffNavMesh)
            {
                longestOffNavMesh = walker.mOffNavMeshFrames;
                longestOffNavMeshAgent = walker.mID;
                longestOffNavMeshFrame = frame;
            }
            // An agent with no polygon under it says it waits for navmesh (OffNavMesh), so that its game
            // knows why it stands. It said NoPath for a frame in a rework of the crowd's path results (an
            // agent whose tile went while its path request was pending), which this scenario meets only by
            // chance: the last test below makes it certain. This check and the next fail on it
            if (noPolygon && state != AgentState::OffNavMesh && mislabelled++ == 0)
            {
                firstMislabelledFrame = frame;
                firstMislabelledAgent = walker.mID;
                firstMislabelledState = int(state);
            }
            // On the navmesh unless waiting for it (every 10 frames: a query with a tiny extent each)
            if (frame % 10 == 0 && state != AgentState::OffNavMesh)
            {
                ++offNavMeshChecks;
                const Result<Vec3> nearest = mWorld->FindNearestPoint(position, {}, Vec3(0.1f, 0.5f, 0.1f));
                if (!nearest || (nearest.Value() - position).norm() >= 0.05f)
                {
                    if (offTheNavMesh++ == 0)
                    {
                        firstOffTheNavMeshFrame = frame;
                        firstOffTheNavMeshAgent = walker.mID;
                    }
                }
            }
            // In no static body (every other frame: an agent walks 6 cm a frame, into a body and out of it in
            // no less than half a second)
            if (frame % 2 == 0)
            {
                const bool checked = mPhysics->GetWorldQuery()
                                         .CollideSphere(position + Vec3(0, cChestHeight, 0), cBodyCheckRadius,
                                                        hits, staticOnly)
                                         .IsOk();
                if (!checked || !hits.empty())
                {
                    ++agentsInBodies;
                    if (firstInBodyFrame < 0)
                    {
                        firstInBodyFrame = frame;
                        ADD_FAILURE()
                            << "agent " << walker.mID << " at (" << position.x() << ", " << position.y()
                            << ", " << position.z() << ") is in a static body, frame " << frame;
                    }
                }
            }
            // At its goal: a new one. An agent whose path ended short of its goal (it led into a tile that
            // was streamed out) or found none asks again every half second, as a game's AI would
            if (!walker.mHasGoal || Flat(position - walker.mGoal).norm() < cAtGoal)
            {
                if (walker.mHasGoal)
                {
                    ++goalsReached;
                    firstGoalsReached += walker.mFirstGoal ? 1 : 0;
                    earlyGoalsReached += walker.mGoalFrame <= cLastEarlyGoalFrame ? 1 : 0;
                    walker.mFirstGoal = false;
                }
                const std::optional<Vec3> goal = PickGoal(position);
                walker.mHasGoal = goal.has_value();
                goalsNotDrawn += walker.mHasGoal ? 0 : 1;
                if (!walker.mHasGoal) continue;
                walker.mGoal = *goal;
                walker.mGoalFrame = frame;
                ++goalsAssigned;
                earlyGoals += frame <= cLastEarlyGoalFrame ? 1 : 0;
                ASSERT_TRUE(crowd->SetTarget(walker.mID, walker.mGoal).IsOk());
            }
            else if ((state == AgentState::NoPath || state == AgentState::Arrived ||
                      state == AgentState::Idle) &&
                     frame >= walker.mRetryFrame)
            {
                walker.mRetryFrame = frame + 30;
                ++retries;
                ASSERT_TRUE(crowd->SetTarget(walker.mID, walker.mGoal).IsOk());
            }
        }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const Crowd::Statistics& statistics = crowd->GetStatistics();
    std::printf(
        "crowd streaming: %d frames, %d agents, %.1f s: goals reached %d of %d given (first goals %d of "
        "%d), overlapping agent-frames %llu of %llu (%.3f %%), longest off the navmesh %d frames, "
        "agents off the navmesh %d of %d checks, not OffNavMesh with no polygon %d, in static bodies %d, "
        "invalid corridors in %d frames, "
        "replans %llu, retries %d, paths applied %llu failed %llu, tiles streamed %d, crates %d "
        "(%d refused), tiles rebuilt %llu; goals given 20 s before the end reached %d of %d, goals not drawn "
        "%d\n",
        cFrames, cNumAgents, seconds, goalsReached, goalsAssigned, firstGoalsReached, cNumAgents,
        (unsigned long long)overlappingAgentFrames, (unsigned long long)agentFrames,
        100.0 * double(overlappingAgentFrames) / double(agentFrames), longestOffNavMesh, offTheNavMesh,
        offNavMeshChecks, mislabelled, agentsInBodies, invalidCorridorFrames,
        (unsigned long long)statistics.mReplans, retries, (unsigned long long)statistics.mPathsApplied,
        (unsigned long long)statistics.mPathsFailed, tilesStreamed, cratesDropped, cratesRefused,
        (unsigned long long)mScheduler->GetStats().mRebuilds, earlyGoalsReached, earlyGoals, goalsNotDrawn);

    EXPECT_EQ(invalidCorridorFrames, 0) << "first at frame " << firstInvalidCorridorFrame;
    EXPECT_EQ(agentsInBodies, 0) << "first at frame " << firstInBodyFrame;
    EXPECT_LE(longestOffNavMesh, 60) << "frames, agent " << longestOffNavMeshAgent << " until frame "
                                     << longestOffNavMeshFrame;
    EXPECT_EQ(mislabelled, 0) << "agent-frames with no polygon under the agent and a state other than "
                                 "OffNavMesh; the first: agent "
                              << firstMislabelledAgent << ", frame " << firstMislabelledFrame << ", state "
                              << firstMislabelledState;
    EXPECT_EQ(offTheNavMesh, 0) << "first agent " << firstOffTheNavMeshAgent << " at frame "
                                << firstOffTheNavMeshFrame;
    EXPECT_LT(overlappingAgentFrames, agentFrames / 100);
    EXPECT_GE(firstGoalsReached, cNumAgents * 95 / 100);
    EXPECT_GE(earlyGoalsReached, earlyGoals * 95 / 100);
    // The scenario did what it says: agents replanned round changed tiles and waited on streamed-out ones,
    // crates fell, and the props came back
    EXPECT_GT(statistics.mReplans, 0u);
    EXPECT_GT(statistics.mOffNavMeshFrames, 0u);
    EXPECT_GT(cratesDropped, cFrames / 90 / 2);
    EXPECT_TRUE(mPropsOut.empty());
}

// What the streaming test above meets by chance, made certain: an agent whose tile is removed while its path
// request is pending has no polygon under it after the next Update, and says so (OffNavMesh). A rework of the
// crowd's path results said NoPath here for a frame (it took the request's failed result after the corridor
// checks); the streaming test found it
TEST_F(CrowdStreamingTest, AnAgentWhoseTileGoesWhileItsPathIsPendingSaysOffNavMesh)
{
    AddStaticBox(Vec3(0, -0.5f, 0), Vec3(12, 0.5f, 12));
    MakeNavMesh(1);
    ASSERT_TRUE(RunUntilIdle());
    std::unique_ptr<Crowd> crowd = Crowd::Create(*mWorld).Value();
    const Crowd::AgentID agent = crowd->AddAgent(Vec3(-6, 0, -6)).Value();
    ASSERT_TRUE(crowd->SetTarget(agent, Vec3(6, 0, 6)).IsOk());
    ASSERT_EQ(crowd->GetState(agent).Value(), AgentState::WaitingForPath);
    mWorld->Publish(Changes(NavMeshWorld::Removal(mWorld->GetGrid().TileAt(-6, -6))));
    for (int frame = 0; frame < 3; ++frame)
    {
        ASSERT_TRUE(crowd->Update(cDeltaTime).IsOk());
        EXPECT_TRUE(crowd->GetCorridor(agent).Value().empty());
        EXPECT_EQ(crowd->GetState(agent).Value(), AgentState::OffNavMesh)
            << "frame " << frame << " (4: NoPath, 5: OffNavMesh)";
    }
}

} // namespace
} // namespace cairn::navmesh::test
