// Hostile input to the navmesh pipeline, beyond NavMeshBadInputTest and TileSchedulerTest. It proves that an
// invoker or kept area the scheduler accepts really gets its tiles (a radius or box past the tile-list
// cut-off must be refused, not silently need nothing); that moving an invoker to nowhere, or moving or
// removing an unknown invoker or area, is an error that changes nothing; that a tile Publish cannot take
// leaves the tile already there in place; that a tile handed in under another coordinate than its data's does
// not desynchronise the world's bookkeeping from Detour's; that tile data with a corrupt header is refused
// before Detour reads it; and that BuildTile refuses a tile grid that NavMeshWorld::Create would refuse.

#include "NavMeshSceneFixture.h"
#include "TileChanges.h"
#include "cairn/navmesh/NavMeshPreview.h"
#include "cairn/navmesh/TileBuilder.h"

#include <DetourAlloc.h>
#include <DetourNavMesh.h>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <gtest/gtest.h>
#include <limits>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

/// A flat 10 m square in tile (0, 0) of inGrid, built with the default profile.
BuiltTile BuildFlatTile(const TileGrid& inGrid)
{
    TileGeometry geometry;
    geometry.AddTriangle(Vec3(0, 0, 0), Vec3(0, 0, 10), Vec3(10, 0, 0), cDefaultArea);
    geometry.AddTriangle(Vec3(10, 0, 0), Vec3(0, 0, 10), Vec3(10, 0, 10), cDefaultArea);
    Result<BuiltTile> built = BuildTile(AgentProfile{}, inGrid, {0, 0}, geometry);
    EXPECT_TRUE(built.IsOk());
    EXPECT_NE(built.Value().mData, nullptr);
    return std::move(built.Value());
}

/// A copy of inTile's data (Detour-allocated, as BuiltTile owns it), changed by inCorrupt.
template <class F> BuiltTile CopyTile(const BuiltTile& inTile, F&& inCorrupt)
{
    BuiltTile copy;
    copy.mTile = inTile.mTile;
    copy.mDataSize = inTile.mDataSize;
    copy.mNumPolygons = inTile.mNumPolygons;
    copy.mNumVertices = inTile.mNumVertices;
    auto* data = static_cast<unsigned char*>(dtAlloc(size_t(inTile.mDataSize), DT_ALLOC_PERM));
    std::memcpy(data, inTile.mData.get(), size_t(inTile.mDataSize));
    dtMeshHeader header;
    std::memcpy(&header, data, sizeof(header));
    inCorrupt(header);
    std::memcpy(data, &header, sizeof(header));
    copy.mData.reset(data);
    return copy;
}

/// inTile's data rebuilt without its links section and with maxLinkCount 0: every other section intact and
/// where the header's counts put it, so only the missing links are wrong.
BuiltTile WithoutLinks(const BuiltTile& inTile)
{
    const unsigned char* source = inTile.mData.get();
    dtMeshHeader header;
    std::memcpy(&header, source, sizeof(header));
    auto padded = [](size_t inBytes) { return (inBytes + 3) & ~size_t(3); };
    const size_t headerBytes = padded(sizeof(dtMeshHeader));
    const size_t beforeLinks = padded(3 * sizeof(float) * size_t(header.vertCount)) +
                               padded(sizeof(dtPoly) * size_t(header.polyCount));
    const size_t linkBytes = padded(sizeof(dtLink) * size_t(header.maxLinkCount));
    const size_t afterLinks = size_t(inTile.mDataSize) - headerBytes - beforeLinks - linkBytes;
    header.maxLinkCount = 0;
    BuiltTile copy;
    copy.mTile = inTile.mTile;
    copy.mNumPolygons = inTile.mNumPolygons;
    copy.mNumVertices = inTile.mNumVertices;
    copy.mDataSize = int(headerBytes + beforeLinks + afterLinks);
    auto* data = static_cast<unsigned char*>(dtAlloc(size_t(copy.mDataSize), DT_ALLOC_PERM));
    std::memset(data, 0, headerBytes);
    std::memcpy(data, &header, sizeof(header));
    std::memcpy(data + headerBytes, source + headerBytes, beforeLinks);
    std::memcpy(data + headerBytes + beforeLinks, source + headerBytes + beforeLinks + linkBytes, afterLinks);
    copy.mData.reset(data);
    return copy;
}

class NavMeshHostileInputTest : public NavMeshSceneFixture
{
protected:
    /// A floor of 4 x 4 tiles and no kept area, as TileSchedulerTest's.
    void MakeFloorWorld()
    {
        AddStaticBox(Vec3(0, -0.5f, 0), Vec3(25.6f, 0.5f, 25.6f));
        MakeNavMesh(2);
        ASSERT_TRUE(mScheduler->RemoveArea(mArea).IsOk());
        ASSERT_EQ(mScheduler->CountNeededNeverPublished(), 0u);
    }
};

TEST_F(NavMeshHostileInputTest, AnInvokerWithAnAcceptedRadiusNeedsTheTilesAroundIt)
{
    MakeFloorWorld();
    // In AddInvoker's range [0, 1e5] m, but its square spans more tiles than the scheduler lists (4096)
    const Result<TileScheduler::InvokerID> invoker = mScheduler->AddInvoker(Vec3(2, 0, 2), 500.0f);
    if (!invoker.IsOk())
    {
        EXPECT_EQ(invoker.GetError().mCode, ErrorCode::InvalidArgument) << "a clear refusal is fine";
        return;
    }
    EXPECT_GT(mScheduler->CountNeededNeverPublished(), 0u)
        << "accepted, yet not even the tile under the invoker is needed";
    EXPECT_FALSE(mScheduler->IsIdle()) << "idle with an invoker standing on unbuilt ground";
}

TEST_F(NavMeshHostileInputTest, AnAcceptedAreaNeedsItsTiles)
{
    MakeFloorWorld();
    // Inside the world's coordinates, but more tiles than the scheduler lists (65536)
    const Result<TileScheduler::AreaID> area =
        mScheduler->AddArea(AABB(Vec3(-2000, -5, -2000), Vec3(2000, 20, 2000)));
    if (!area.IsOk())
    {
        EXPECT_EQ(area.GetError().mCode, ErrorCode::InvalidArgument) << "a clear refusal is fine";
        return;
    }
    EXPECT_GT(mScheduler->CountNeededNeverPublished(), 0u) << "accepted, yet no tile of it is needed";
    EXPECT_FALSE(mScheduler->IsIdle());
}

TEST_F(NavMeshHostileInputTest, AnInvokerAtTheRadiusLimitNeedsEveryTileWithinIt)
{
    MakeFloorWorld();
    const TileGrid& grid = mWorld->GetGrid();
    const float limit = float(TileScheduler::cMaxInvokerReachTiles) * grid.GetTileSize(); // 384 m
    EXPECT_FALSE(mScheduler->AddInvoker(Vec3(0, 0, 0), std::nextafter(limit, 1e6f)).IsOk())
        << "past the limit";
    // At the limit, standing on a tile's corner (where the radius reaches furthest into other tiles) and
    // inside one: every tile within the radius is needed, as a brute-force count over the grid says
    for (const Vec3& position : {Vec3(grid.GetOriginX() + 40.0f * grid.GetTileSize(), 0,
                                      grid.GetOriginZ() + 40.0f * grid.GetTileSize()),
                                 Vec3(503.3f, 0, -731.9f)})
    {
        const Result<TileScheduler::InvokerID> invoker = mScheduler->AddInvoker(position, limit);
        ASSERT_TRUE(invoker.IsOk()) << invoker.GetError().mMessage;
        const TileCoord centre = grid.TileAt(position.x(), position.z());
        uint32_t within = 0;
        for (int32_t z = centre.mZ - 40; z <= centre.mZ + 40; ++z)
            for (int32_t x = centre.mX - 40; x <= centre.mX + 40; ++x)
            {
                const AABB box = grid.GetTileBounds({x, z});
                const float dx = std::max({box.mMin.x() - position.x(), 0.0f, position.x() - box.mMax.x()});
                const float dz = std::max({box.mMin.z() - position.z(), 0.0f, position.z() - box.mMax.z()});
                if (std::sqrt(dx * dx + dz * dz) <= limit) ++within;
            }
        EXPECT_GT(within, 2000u);
        EXPECT_EQ(mScheduler->CountNeededNeverPublished(), within) << position.transpose();
        ASSERT_TRUE(mScheduler->RemoveInvoker(invoker.Value()).IsOk());
    }
}

TEST_F(NavMeshHostileInputTest, MovesAndRemovalsOfUnknownInvokersAndAreasOrToNowhereAreErrors)
{
    MakeFloorWorld();
    const Result<TileScheduler::InvokerID> invoker = mScheduler->AddInvoker(Vec3(2, 0, 2), 5.0f);
    ASSERT_TRUE(invoker.IsOk());
    const size_t needed = mScheduler->CountNeededNeverPublished();
    ASSERT_GT(needed, 0u);
    // A NaN or far-off position is refused, and the invoker stays where it was
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(mScheduler->MoveInvoker(invoker.Value(), Vec3(nan, 0, 0)).GetError().mCode,
              ErrorCode::InvalidArgument);
    EXPECT_EQ(mScheduler->MoveInvoker(invoker.Value(), Vec3(1e9f, 0, 0)).GetError().mCode,
              ErrorCode::InvalidArgument);
    EXPECT_EQ(mScheduler->CountNeededNeverPublished(), needed);
    // Ids that were never handed out, or were removed already
    const TileScheduler::InvokerID unknown = invoker.Value() + 1000;
    EXPECT_EQ(mScheduler->MoveInvoker(unknown, Vec3(2, 0, 2)).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(mScheduler->RemoveInvoker(unknown).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_TRUE(mScheduler->RemoveInvoker(invoker.Value()).IsOk());
    EXPECT_EQ(mScheduler->RemoveInvoker(invoker.Value()).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(mScheduler->MoveInvoker(invoker.Value(), Vec3(2, 0, 2)).GetError().mCode,
              ErrorCode::InvalidArgument);
    EXPECT_EQ(mScheduler->RemoveArea(mArea).GetError().mCode, ErrorCode::InvalidArgument)
        << "removed already";
}

TEST(NavMeshHostileInputWorldTest, TilesDetourCanNotTakeLeaveTheOldOneInPlace)
{
    const AgentProfile profile;
    const TileGrid grid(0, 0, profile.mTileSize, -1, 10);
    auto world = NavMeshWorld::Create(grid, profile);
    ASSERT_TRUE(world);
    const BuiltTile good = BuildFlatTile(grid);
    ASSERT_EQ(world.Value()->Publish(Changes(CopyTile(good, [](dtMeshHeader&) {}))), 1);
    const int polygons = world.Value()->GetTilePolygonCount({0, 0});
    ASSERT_GT(polygons, 0);

    // Not Detour data at all (its magic number is gone): Detour refuses it without reading further
    (void)world.Value()->Publish(Changes(CopyTile(good, [](dtMeshHeader& ioHeader) { ioHeader.magic = 0; })));
    EXPECT_EQ(world.Value()->GetRefusedTiles(), 1u);
    EXPECT_EQ(world.Value()->GetTilePolygonCount({0, 0}), polygons)
        << "the refused tile took the good one with it: a hole in the navmesh";
    EXPECT_TRUE(world.Value()->FindNearestPoint(Vec3(5, 0, 5)).IsOk()) << "no navmesh left at (5, 0, 5)";

    // Whole and consistent but with no room for links: addTile would end its free list before the section
    // and hand out links over the detail meshes
    EXPECT_EQ(world.Value()->Publish(Changes(WithoutLinks(good))), 0);
    EXPECT_EQ(world.Value()->GetRefusedTiles(), 2u);
    EXPECT_EQ(world.Value()->GetTilePolygonCount({0, 0}), polygons);
    EXPECT_TRUE(world.Value()->FindNearestPoint(Vec3(5, 0, 5)).IsOk());
}

TEST(NavMeshHostileInputWorldTest, ATileHandedInUnderAnotherCoordinateKeepsTheBookkeepingTrue)
{
    const AgentProfile profile;
    const TileGrid grid(0, 0, profile.mTileSize, -1, 10);
    auto world = NavMeshWorld::Create(grid, profile);
    ASSERT_TRUE(world);
    NavMeshWorld& navMesh = *world.Value();
    // Data built for tile (0, 0), handed in as tile (3, 3)
    BuiltTile mislabelled = BuildFlatTile(grid);
    mislabelled.mTile = {3, 3};
    (void)navMesh.Publish(Changes(std::move(mislabelled)));
    const bool navMeshAtOrigin = navMesh.FindNearestPoint(Vec3(5, 0, 5)).IsOk();
    EXPECT_FALSE(navMesh.HasTile({3, 3})) << "reported at (3, 3), where Detour has nothing";
    EXPECT_EQ(navMesh.HasTile({0, 0}), navMeshAtOrigin)
        << "Detour has a tile at (0, 0) the world does not list";
    EXPECT_EQ(navMesh.GetNumTiles(), int(navMesh.SnapshotTiles().size()));

    // Removing it by the coordinate it was handed in under must remove it
    (void)navMesh.Publish(Changes(NavMeshWorld::Removal({3, 3})));
    EXPECT_EQ(navMesh.GetNumTiles(), 0) << "the world still lists it";
    EXPECT_TRUE(navMesh.SnapshotTiles().empty()) << "Detour still holds it: it can never be removed";
    EXPECT_FALSE(navMesh.FindNearestPoint(Vec3(5, 0, 5)).IsOk()) << "paths still use it";
}

TEST(NavMeshHostileInputWorldTest, OfATileListedTwiceInOnePublishTheLastChangeWins)
{
    const AgentProfile profile;
    const TileGrid grid(0, 0, profile.mTileSize, -1, 10);
    auto world = NavMeshWorld::Create(grid, profile);
    ASSERT_TRUE(world);
    NavMeshWorld& navMesh = *world.Value();
    const BuiltTile good = BuildFlatTile(grid);
    std::vector<BuiltTile> builtThenRemoved;
    builtThenRemoved.push_back(CopyTile(good, [](dtMeshHeader&) {}));
    builtThenRemoved.push_back(NavMeshWorld::Removal({0, 0}));
    EXPECT_EQ(navMesh.Publish(std::move(builtThenRemoved)), 0);
    EXPECT_FALSE(navMesh.HasTile({0, 0}));
    std::vector<BuiltTile> removedThenBuilt;
    removedThenBuilt.push_back(NavMeshWorld::Removal({0, 0}));
    removedThenBuilt.push_back(CopyTile(good, [](dtMeshHeader&) {}));
    EXPECT_EQ(navMesh.Publish(std::move(removedThenBuilt)), 1);
    EXPECT_TRUE(navMesh.HasTile({0, 0}));
    EXPECT_EQ(navMesh.Publish({}), 0) << "nothing to change";
}

TEST(NavMeshHostileInputWorldTest, BuildTileRefusesAGridTheWorldWouldRefuse)
{
    const AgentProfile profile;
    TileGeometry geometry;
    geometry.AddTriangle(Vec3(0, 0, 0), Vec3(0, 0, 10), Vec3(10, 0, 0), cDefaultArea);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const TileGrid nanOrigin(nan, 0, profile.mTileSize, -1, 10);
    const TileGrid otherTileSize(0, 0, 4.0f * profile.mTileSize, -1, 10);
    const TileGrid upsideDown(0, 0, profile.mTileSize, 10, -1);
    ASSERT_FALSE(NavMeshWorld::Create(nanOrigin, profile));
    ASSERT_FALSE(NavMeshWorld::Create(otherTileSize, profile));
    ASSERT_FALSE(NavMeshWorld::Create(upsideDown, profile));
    for (const auto& [grid, name] :
         {std::pair{&nanOrigin, "NaN origin"}, std::pair{&otherTileSize, "tile size"},
          std::pair{&upsideDown, "min y above max y"}})
    {
        const Result<BuiltTile> built = BuildTile(profile, *grid, {0, 0}, geometry);
        EXPECT_FALSE(built.IsOk()) << name << ": built a tile of " << built.Value().mNumPolygons
                                   << " polygons on a grid the navmesh world refuses";
    }
}

/// Hands the world tile data whose header claims 1000 more vertices than it holds; exits 0 when Publish
/// refused it, 1 when Detour took it (and read past the buffer).
[[noreturn]] void PublishATileWithACorruptHeader()
{
    const AgentProfile profile;
    const TileGrid grid(0, 0, profile.mTileSize, -1, 10);
    auto world = NavMeshWorld::Create(grid, profile);
    if (!world) std::exit(2);
    const BuiltTile good = BuildFlatTile(grid);
    const int changed = world.Value()->Publish(
        Changes(CopyTile(good, [](dtMeshHeader& ioHeader) { ioHeader.vertCount += 1000; })));
    // Use what Detour linked, as a path query would
    (void)world.Value()->FindNearestPoint(Vec3(5, 0, 5));
    world.Value()->Read([](const dtNavMesh& inNavMesh) { (void)NavMeshToObj(inNavMesh); });
    std::exit(changed == 0 && world.Value()->GetRefusedTiles() == 1 ? 0 : 1);
}

TEST(NavMeshHostileInputDeathTest, TileDataWithACorruptHeaderIsRefusedBeforeDetourReadsIt)
{
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    EXPECT_EXIT(PublishATileWithACorruptHeader(), ::testing::ExitedWithCode(0), "")
        << "exit code 1: Publish handed the corrupt tile to Detour; a signal: it crashed";
}

} // namespace
} // namespace cairn::navmesh::test
