// The detail surface's measured distance from the voxels (BuiltTile::mMaxDetailError) and its resampling:
// - a flat floor measures (next to) nothing and resamples nothing: the measure and Recast's detail heights
//   share their origin;
// - a step the agent climbs measures part of the step: the measure sees the voxels' heights;
// - stacks of two climbable steps (a crate on a platform, at several places on it) end within one climb of
//   the voxels, every polygon.

#include "cairn/navmesh/GeometryCollector.h"
#include "cairn/navmesh/TileBuilder.h"
#include "cairn/physics/PhysicsSystem.h"
#include "common/MakePhysicsSystem.h"
#include "common/StaticFloor.h"

#include <gtest/gtest.h>

namespace cairn::navmesh
{
using namespace cairn::physics;
namespace
{

using cairn::test::BoxBodySettings;

struct DetailHeightsScene
{
    DetailHeightsScene() : mPhysics(cairn::test::MakePhysicsSystem())
    {
        EXPECT_TRUE(mPhysics->GetBodyInterface().CreateAndAddBody(cairn::test::StaticFloorSettings(40.0f),
                                                                  Activation::DontActivate));
    }
    void AddBox(const Vec3& inCenter, const Vec3& inHalfExtent)
    {
        EXPECT_TRUE(mPhysics->GetBodyInterface().CreateAndAddBody(
            BoxBodySettings(inCenter, inHalfExtent, MotionType::Static), Activation::DontActivate));
    }
    /// Tile (0, 0): x and z from 0 to 12.8 m.
    BuiltTile Build() const
    {
        const TileGrid grid(0.0f, 0.0f, mProfile.mTileSize, -2.0f, 10.0f);
        const TileCoord tile{0, 0};
        const AABB box =
            grid.GetTileBoundsWithBorder(tile, float(mProfile.GetBorderCells()) * mProfile.mCellSize);
        const GeometryCollector collector(mPhysics->GetBodyManager(), mPhysics->GetBroadPhase());
        std::vector<BodyID> bodies;
        TileGeometry geometry;
        CollectStats stats;
        collector.FindBodies(box, {}, bodies);
        collector.CollectTriangles(box, {}, bodies, geometry, stats);
        Result<BuiltTile> built = BuildTile(mProfile, grid, tile, geometry);
        EXPECT_TRUE(built) << built.GetError().mMessage;
        return built ? std::move(built).Value() : BuiltTile{};
    }

    AgentProfile mProfile;
    std::unique_ptr<PhysicsSystem> mPhysics;
};

TEST(DetailHeightsTest, AFlatFloorMeasuresNothingAndResamplesNothing)
{
    const DetailHeightsScene scene;
    const BuiltTile tile = scene.Build();
    ASSERT_GT(tile.mNumPolygons, 0);
    EXPECT_LT(tile.mMaxDetailError, 0.01f);
    EXPECT_EQ(tile.mResampledPolygons, 0);
    EXPECT_EQ(tile.mRoughPolygons, 0);
}

TEST(DetailHeightsTest, AClimbableStepIsMeasured)
{
    DetailHeightsScene scene;
    scene.AddBox(Vec3(6.4f, 0.3f, 6.4f), Vec3(2.0f, 0.3f, 2.0f)); // 0.6 m: under the 0.9 m climb
    const BuiltTile tile = scene.Build();
    ASSERT_GT(tile.mNumPolygons, 0);
    // The step's cells are a ramp's width from the voxels: part of the step at least, never more than it
    EXPECT_GT(tile.mMaxDetailError, 0.2f);
    EXPECT_LE(tile.mMaxDetailError, 0.6f + scene.mProfile.mCellHeight);
}

TEST(DetailHeightsTest, CratesOnAPlatformEndWithinOneClimbOfTheVoxels)
{
    // A crate 0.7 m high on a platform 0.6 m high, at places over the platform: 84 tiles
    int resampled = 0;
    for (int i = 0; i < 14; ++i)
        for (int j = 0; j < 6; ++j)
        {
            const Vec3 crate(4.4f + 0.3f * float(i), 0.95f, 4.4f + 0.7f * float(j));
            SCOPED_TRACE("crate at x " + std::to_string(crate.x()) + ", z " + std::to_string(crate.z()));
            DetailHeightsScene scene;
            scene.AddBox(Vec3(6.4f, 0.3f, 6.4f), Vec3(2.0f, 0.3f, 2.0f));
            scene.AddBox(crate, Vec3(0.5f, 0.35f, 0.5f));
            const BuiltTile tile = scene.Build();
            ASSERT_GT(tile.mNumPolygons, 0);
            EXPECT_EQ(tile.mRoughPolygons, 0);
            EXPECT_LE(tile.mMaxDetailError, scene.mProfile.mMaxClimb);
            resampled += tile.mResampledPolygons;
        }
    // One of them (the crate at x 7.4, z 6.5, half a metre from the platform's edge) has Recast's detail
    // surface more than a climb under the crate's top: without the resampling, its tile fails the bound
    EXPECT_GT(resampled, 0);
}

} // namespace
} // namespace cairn::navmesh
