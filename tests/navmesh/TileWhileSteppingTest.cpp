// A tile built while the world steps back to back equals, byte for byte, the tile built from the same
// published state with the world still.
//
// The scene: one 12.8 m navmesh tile over a static floor with a few static boxes and six sleeping dynamic
// crates (added with Activation::DontActivate: asleep, so their published pose never changes, and the default
// NavMeshInclusion takes sleeping dynamic bodies, so they are obstacles in the tile). Inside the tile, away
// from the crates, bodies the default inclusion leaves out move all the time: a spinning kinematic paddle, a
// sphere bouncing on the floor and a box resting on it (both dynamic with sleeping off, so awake). Outside
// the tile's bordered box, a pile of awake dynamic boxes that a kinematic piston pushes back and forth, so
// every step does real work and publishes hundreds of poses.
// Threads:
//  - a step thread runs Update back to back, setting a flag around each one and counting them;
//  - the test thread builds the tile K times meanwhile (GeometryCollector::FindBodies and CollectTriangles
//    over the tile's bordered box, then BuildTile), keeping only builds whose collection overlapped a step
//    (the flag set at its start or end, or the count moved across it), then stops the step thread and builds
//    the tile once more from the still world.
// Every concurrent build's geometry and tile data (BuiltTile::mData, mDataSize bytes) must equal the still
// build's. The crates matter: the tile built without sleeping dynamic bodies has fewer triangles and other
// data. The crates stayed asleep, with the published version they started with, for the whole run.
// Part of the navmesh suite; also clean under ThreadSanitizer (the collector reads the records of the moving
// bodies in the tile while the step publishes them).

#include "cairn/navmesh/GeometryCollector.h"
#include "cairn/navmesh/TileBuilder.h"
#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/body/PublishedPose.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "common/MakePhysicsSystem.h"
#include "common/StaticFloor.h"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <gtest/gtest.h>
#include <string>
#include <thread>
#include <vector>

namespace cairn::navmesh
{
using namespace cairn::physics;
namespace
{

using cairn::test::BoxBodySettings;

/// One tile build: what was collected and what Recast and Detour made of it.
struct TileBuild
{
    TileGeometry mGeometry;
    CollectStats mStats;
    size_t mBodiesFound = 0; ///< FindBodies' count, the bodies left out included
    BuiltTile mTile;
};

TileBuild BuildTileNow(const PhysicsSystem& inSystem, const AgentProfile& inProfile, const TileGrid& inGrid,
                       const TileCoord& inTile, const NavMeshInclusion& inInclusion)
{
    const GeometryCollector collector(inSystem.GetBodyManager(), inSystem.GetBroadPhase());
    const AABB box =
        inGrid.GetTileBoundsWithBorder(inTile, float(inProfile.GetBorderCells()) * inProfile.mCellSize);
    TileBuild build;
    std::vector<BodyID> bodies;
    collector.FindBodies(box, inInclusion, bodies);
    build.mBodiesFound = bodies.size();
    collector.CollectTriangles(box, inInclusion, bodies, build.mGeometry, build.mStats);
    return build;
}

bool SameGeometry(const TileGeometry& inA, const TileGeometry& inB)
{
    return inA.mVertices == inB.mVertices && inA.mTriangles == inB.mTriangles && inA.mAreas == inB.mAreas;
}

bool SameTileData(const BuiltTile& inA, const BuiltTile& inB)
{
    if (inA.mDataSize != inB.mDataSize || (inA.mData == nullptr) != (inB.mData == nullptr)) return false;
    return inA.mData == nullptr || std::memcmp(inA.mData.get(), inB.mData.get(), size_t(inA.mDataSize)) == 0;
}

TEST(TileWhileSteppingTest, TileBuiltWhileTheWorldStepsEqualsTheStillWorldsTile)
{
    PhysicsSettings settings;
    settings.mMaxBodies = 1024;
    const std::unique_ptr<PhysicsSystem> system = cairn::test::MakePhysicsSystem(settings);
    BodyInterface& bodies = system->GetBodyInterface();

    const AgentProfile profile;
    const TileGrid grid(0.0f, 0.0f, profile.mTileSize, -2.0f, 10.0f);
    const TileCoord tile{0, 0}; // x and z in [0, 12.8], bordered box [-1.2, 14]

    // The still part of the tile: floor (reaching the outside pile too) and static boxes
    ASSERT_TRUE(bodies.CreateAndAddBody(cairn::test::StaticFloorSettings(60.0f), Activation::DontActivate));
    for (const auto& [center, halfExtent] : {std::pair{Vec3(3.0f, 0.75f, 9.0f), Vec3(0.6f, 0.75f, 1.5f)},
                                             std::pair{Vec3(9.0f, 0.5f, 3.0f), Vec3(1.2f, 0.5f, 0.4f)},
                                             std::pair{Vec3(6.4f, 1.0f, 11.0f), Vec3(0.5f, 1.0f, 0.5f)}})
        ASSERT_TRUE(bodies.CreateAndAddBody(BoxBodySettings(center, halfExtent, MotionType::Static),
                                            Activation::DontActivate));

    // The sleeping crates, resting on the floor, 1 m high (higher than the agent climbs: obstacles)
    std::vector<BodyID> crates;
    const Vec3 cratePositions[] = {Vec3(2.0f, 0.5f, 2.0f), Vec3(4.0f, 0.5f, 3.5f), Vec3(2.5f, 0.5f, 5.5f),
                                   Vec3(6.0f, 0.5f, 6.0f), Vec3(8.0f, 0.5f, 8.5f), Vec3(10.5f, 0.5f, 6.5f)};
    for (size_t i = 0; i < std::size(cratePositions); ++i)
    {
        BodyCreationSettings crate =
            BoxBodySettings(cratePositions[i], Vec3(0.5f, 0.5f, 0.5f), MotionType::Dynamic);
        crate.mRotation = Quat(Eigen::AngleAxisf(0.25f * float(i), Vec3::UnitY()));
        crates.push_back(bodies.CreateAndAddBody(crate, Activation::DontActivate).Value());
    }

    // Moving in the tile, all left out by the default inclusion, and well clear of every crate (a touch would
    // wake it)
    BodyCreationSettings paddle =
        BoxBodySettings(Vec3(10.0f, 0.5f, 11.0f), Vec3(1.2f, 0.25f, 0.2f), MotionType::Kinematic);
    const BodyID paddleID = bodies.CreateAndAddBody(paddle, Activation::Activate).Value();
    ASSERT_TRUE(bodies.SetAngularVelocity(paddleID, Vec3(0.0f, 1.5f, 0.0f)));
    BodyCreationSettings bouncer;
    bouncer.mShape = SphereShape::Create(0.3f).Value();
    bouncer.mPosition = Vec3(11.5f, 2.0f, 1.5f);
    bouncer.mRestitution = 1.0f; // Straight up and down for the whole run
    bouncer.mLinearDamping = 0.0f;
    bouncer.mAllowSleeping = false;
    ASSERT_TRUE(bodies.CreateAndAddBody(bouncer, Activation::Activate));
    BodyCreationSettings resting =
        BoxBodySettings(Vec3(1.0f, 0.4f, 11.5f), Vec3(0.4f, 0.4f, 0.4f), MotionType::Dynamic);
    resting.mAllowSleeping = false; // Awake, published every step, left out
    ASSERT_TRUE(bodies.CreateAndAddBody(resting, Activation::Activate));

    // Outside the bordered box: a walled pile pushed back and forth by a kinematic piston
    for (float side : {-1.0f, 1.0f})
    {
        ASSERT_TRUE(bodies.CreateAndAddBody(BoxBodySettings(Vec3(35.0f + side * 10.5f, 1.5f, 0.0f),
                                                            Vec3(0.5f, 1.5f, 11.0f), MotionType::Static),
                                            Activation::DontActivate));
        ASSERT_TRUE(bodies.CreateAndAddBody(
            BoxBodySettings(Vec3(35.0f, 1.5f, side * 10.5f), Vec3(11.0f, 1.5f, 0.5f), MotionType::Static),
            Activation::DontActivate));
    }
    for (int i = 0; i < 150; ++i)
    {
        BodyCreationSettings box = BoxBodySettings(
            Vec3(30.0f + float(i % 10), 0.5f + float(i / 50), -7.0f + 2.8f * float((i / 10) % 5)),
            Vec3(0.35f, 0.35f, 0.35f), MotionType::Dynamic);
        box.mAllowSleeping = false;
        ASSERT_TRUE(bodies.CreateAndAddBody(box, Activation::Activate));
    }
    const BodyID piston =
        bodies
            .CreateAndAddBody(
                BoxBodySettings(Vec3(26.5f, 0.8f, 0.0f), Vec3(0.3f, 0.75f, 9.5f), MotionType::Kinematic),
                Activation::Activate)
            .Value();
    ASSERT_TRUE(bodies.SetLinearVelocity(piston, Vec3(2.0f, 0.0f, 0.0f)));

    // The crates are asleep, and stay so: note the version of their published pose
    std::vector<uint32_t> crateVersions;
    for (const BodyID& crate : crates)
    {
        ASSERT_FALSE(bodies.IsActive(crate).Value());
        const PoseReader reader(system->GetBodyManager());
        PublishedPose pose;
        ASSERT_TRUE(reader.Read(crate, pose));
        crateVersions.push_back(pose.mVersion);
    }

    // Relaxed for the stop flag; the flag and the count are read around each collection
    std::atomic<bool> stop{false};
    // Seq-cst (the default): a label around each Update, the plainest to reason about
    std::atomic<bool> stepping{false};
    std::atomic<uint64_t> updates{0};
    std::atomic<uint64_t> failedUpdates{0};
    std::thread stepThread(
        [&]
        {
            uint64_t count = 0, pistonTurns = 0;
            while (!stop.load(std::memory_order_relaxed))
            {
                stepping.store(true);
                failedUpdates.fetch_add(system->Update(1.0f / 60.0f) ? 0 : 1, std::memory_order_relaxed);
                stepping.store(false);
                updates.store(++count);
                // The piston turns round at the ends of its stroke (every 4 s of world time)
                if (count % 240 == 0)
                {
                    ++pistonTurns;
                    const float speed = pistonTurns % 2 == 1 ? -2.0f : 2.0f;
                    failedUpdates.fetch_add(bodies.SetLinearVelocity(piston, Vec3(speed, 0.0f, 0.0f)) ? 0 : 1,
                                            std::memory_order_relaxed);
                }
            }
        });
    // The pile falls and the piston gets going before the first build
    while (updates.load() < 10)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));

    // Builds back to back for at least half a second and 100 updates, and until at least cMinBuilds of them
    // collected while a step ran (at most 20 s). A build whose collection fell between two updates is not
    // counted as concurrent, but compared all the same. No ASSERT while the step thread runs: it must be
    // joined first
    constexpr size_t cMinBuilds = 8;
    std::vector<TileBuild> concurrent, between;
    uint64_t updatesDuringCollections = 0;
    double collectMs = 0.0, buildMs = 0.0;
    std::string buildError;
    uint64_t extraCollections = 0, extraDiffering = 0;
    const uint64_t firstUpdate = updates.load();
    const auto start = std::chrono::steady_clock::now();
    for (;;)
    {
        const auto elapsed = std::chrono::steady_clock::now() - start;
        if (elapsed >= std::chrono::seconds(20)) break;
        if (elapsed >= std::chrono::milliseconds(500) && concurrent.size() >= cMinBuilds &&
            updates.load() - firstUpdate >= 100)
            break;
        const uint64_t updatesBefore = updates.load();
        const bool steppingBefore = stepping.load();
        TileBuild build = BuildTileNow(*system, profile, grid, tile, {});
        const bool steppingAfter = stepping.load();
        const uint64_t updatesAfter = updates.load();
        Result<BuiltTile> built = BuildTile(profile, grid, tile, build.mGeometry);
        if (!built)
        {
            buildError = built.GetError().mMessage;
            break;
        }
        build.mTile = std::move(built.Value());
        collectMs += build.mStats.mCollectMs;
        buildMs += build.mTile.mBuildMs;
        if (steppingBefore || steppingAfter || updatesAfter != updatesBefore)
        {
            updatesDuringCollections += updatesAfter - updatesBefore;
            concurrent.push_back(std::move(build));
        }
        else
            between.push_back(std::move(build));
        // Collections alone are a few microseconds and Recast a few milliseconds: more collections, so that
        // many of them meet the step publishing the moving bodies they read. Each must collect the first
        // build's geometry (which is compared with the still world's below)
        const TileGeometry& first =
            concurrent.empty() ? between.front().mGeometry : concurrent.front().mGeometry;
        for (int i = 0; i < 32; ++i)
        {
            const TileBuild extra = BuildTileNow(*system, profile, grid, tile, {});
            extraDiffering += SameGeometry(extra.mGeometry, first) ? 0 : 1;
            ++extraCollections;
        }
    }
    stop.store(true, std::memory_order_relaxed);
    stepThread.join();
    const uint64_t totalUpdates = updates.load();
    ASSERT_TRUE(buildError.empty()) << buildError;

    // The still world: the same published state of everything the tile takes
    TileBuild still = BuildTileNow(*system, profile, grid, tile, {});
    Result<BuiltTile> stillBuilt = BuildTile(profile, grid, tile, still.mGeometry);
    ASSERT_TRUE(stillBuilt) << stillBuilt.GetError().mMessage;
    still.mTile = std::move(stillBuilt.Value());
    ASSERT_NE(still.mTile.mData, nullptr) << "the tile has no walkable polygon";

    // Without the crates (sleeping dynamic bodies left out)
    NavMeshInclusion noCrates;
    noCrates.mSleepingDynamic = false;
    TileBuild bare = BuildTileNow(*system, profile, grid, tile, noCrates);
    Result<BuiltTile> bareBuilt = BuildTile(profile, grid, tile, bare.mGeometry);
    ASSERT_TRUE(bareBuilt) << bareBuilt.GetError().mMessage;
    bare.mTile = std::move(bareBuilt.Value());

    std::printf(
        "[ figure   ] %zu builds while stepping (%llu updates finished during their collections, %zu more "
        "between updates), %llu updates in all; %u triangles from %u of %zu bodies found, %d polygons, %d "
        "bytes; "
        "without the crates %u triangles, %d polygons; collect %.3f ms, build %.1f ms a tile; %llu "
        "collections alone, %llu of them differing\n",
        concurrent.size(), (unsigned long long)updatesDuringCollections, between.size(),
        (unsigned long long)totalUpdates, still.mStats.mTriangles, still.mStats.mBodies, still.mBodiesFound,
        still.mTile.mNumPolygons, still.mTile.mDataSize, bare.mStats.mTriangles, bare.mTile.mNumPolygons,
        collectMs / double(concurrent.size() + between.size()),
        buildMs / double(concurrent.size() + between.size()), (unsigned long long)extraCollections,
        (unsigned long long)extraDiffering);

    EXPECT_EQ(failedUpdates.load(), 0u);
    EXPECT_EQ(extraDiffering, 0u) << "of " << extraCollections << " collections alone";
    // The builds overlapped steps: the flag or the count says so
    EXPECT_GE(concurrent.size(), cMinBuilds);
    for (size_t i = 0; i < concurrent.size(); ++i)
    {
        EXPECT_TRUE(SameGeometry(concurrent[i].mGeometry, still.mGeometry))
            << "build " << i << ": " << concurrent[i].mStats.mTriangles << " triangles, still "
            << still.mStats.mTriangles;
        EXPECT_TRUE(SameTileData(concurrent[i].mTile, still.mTile))
            << "build " << i << ": " << concurrent[i].mTile.mDataSize << " bytes, "
            << concurrent[i].mTile.mNumPolygons << " polygons; still " << still.mTile.mDataSize << " bytes, "
            << still.mTile.mNumPolygons << " polygons";
    }
    for (const TileBuild& build : between)
        EXPECT_TRUE(SameTileData(build.mTile, still.mTile)) << "a build between two updates";

    // The crates are in the tile: more triangles, and another tile, than without them
    EXPECT_GT(still.mStats.mTriangles, bare.mStats.mTriangles);
    EXPECT_FALSE(SameTileData(still.mTile, bare.mTile)) << "the crates changed nothing in the tile";
    // The moving bodies in the tile were found and read, and left out
    EXPECT_GT(still.mBodiesFound, size_t(still.mStats.mBodies));
    // The crates slept through the run: their published pose is the one the builds were compared against
    const PoseReader reader(system->GetBodyManager());
    for (size_t i = 0; i < crates.size(); ++i)
    {
        PublishedPose pose;
        ASSERT_TRUE(reader.Read(crates[i], pose));
        EXPECT_FALSE(pose.mActive) << "crate " << i << " woke up";
        EXPECT_EQ(pose.mVersion, crateVersions[i]) << "crate " << i << " was published again";
    }
}

} // namespace
} // namespace cairn::navmesh
