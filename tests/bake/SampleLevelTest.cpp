// The sample level in data/ (the README's bake example): every agent profile there loads and bakes the
// courtyard into its four areas, a path climbs the ramp from the road to the terrace, and the tower's roof is
// an island no path reaches.

#include "BakeConfig.h"
#include "Baker.h"
#include "cairn/navmesh/NavMeshFile.h"

#include <DetourNavMesh.h>
#include <DetourNavMeshQuery.h>
#include <Recast.h>
#include <gtest/gtest.h>
#include <set>
#include <string>

namespace cairn::bake
{
using namespace cairn::physics;
namespace
{

const std::string cDataDir = CAIRN_DATA_DIR;

class SampleLevelTest : public ::testing::TestWithParam<const char*>
{
};

/// The areas of the navmesh's polygons.
std::set<int> AreasOf(const dtNavMesh& inMesh)
{
    std::set<int> areas;
    for (int i = 0; i < inMesh.getMaxTiles(); ++i)
        if (const dtMeshTile* tile = inMesh.getTile(i); tile != nullptr && tile->header != nullptr)
            for (int p = 0; p < tile->header->polyCount; ++p)
                areas.insert(tile->polys[p].getArea());
    return areas;
}

TEST_P(SampleLevelTest, BakesIntoItsAreasWithTheRampClimbable)
{
    BakeSettings settings;
    settings.mInputs = {cDataDir + "/levels/courtyard.gltf"};
    settings.mThreads = 2;
    const Status config = LoadBakeConfig(cDataDir + "/agents/" + GetParam() + ".json", settings.mProfile);
    ASSERT_TRUE(config.IsOk()) << config.GetError().mMessage;
    Result<navmesh::AreaMapping> areas = LoadAreaMapping(cDataDir + "/levels/courtyard-areas.json");
    ASSERT_TRUE(areas) << areas.GetError().mMessage;
    settings.mAreas = areas.Value();

    Result<BakeResult> baked = Bake(settings);
    ASSERT_TRUE(baked) << baked.GetError().mMessage;
    EXPECT_EQ(baked.Value().mBodies, 10u) << "a body per object: the level has ten";
    EXPECT_EQ(baked.Value().mTilesInWorld, 16u) << "48 m square in 12.8 m tiles";
    Result<navmesh::DetourNavMeshPtr> navMesh = navmesh::CreateDetourNavMesh(baked.Value().mNavMesh);
    ASSERT_TRUE(navMesh) << navMesh.GetError().mMessage;
    // Road 1, grass 2, the pond 3, the stone roofs the default ground (Recast's walkable area in the file)
    EXPECT_EQ(AreasOf(*navMesh.Value()), (std::set<int>{1, 2, 3, RC_WALKABLE_AREA}));

    dtNavMeshQuery query;
    ASSERT_TRUE(dtStatusSucceed(query.init(navMesh.Value().get(), 4096)));
    const dtQueryFilter filter;
    const float extents[3] = {1.0f, 2.0f, 1.0f};
    auto nearest = [&](float inX, float inY, float inZ, float* outPoint)
    {
        const float point[3] = {inX, inY, inZ};
        dtPolyRef poly = 0;
        EXPECT_TRUE(dtStatusSucceed(query.findNearestPoly(point, extents, &filter, &poly, outPoint)));
        EXPECT_NE(poly, 0u) << "no navmesh near " << inX << ", " << inY << ", " << inZ;
        return poly;
    };
    float road[3], terrace[3], roof[3];
    const dtPolyRef onRoad = nearest(-6.0f, 0.0f, 0.0f, road);
    const dtPolyRef onTerrace = nearest(12.0f, 2.0f, 12.0f, terrace);
    const dtPolyRef onRoof = nearest(-16.0f, 16.0f, -14.0f, roof);
    ASSERT_NE(onRoad, 0u);
    ASSERT_NE(onTerrace, 0u);
    ASSERT_NE(onRoof, 0u);
    EXPECT_NEAR(terrace[1], 2.0f, 0.3f);

    dtPolyRef corridor[256];
    int count = 0;
    dtStatus status = query.findPath(onRoad, onTerrace, road, terrace, &filter, corridor, &count, 256);
    ASSERT_TRUE(dtStatusSucceed(status));
    EXPECT_FALSE(dtStatusDetail(status, DT_PARTIAL_RESULT));
    ASSERT_GT(count, 0);
    EXPECT_EQ(corridor[count - 1], onTerrace) << "the ramp leads up to the terrace";

    status = query.findPath(onRoad, onRoof, road, roof, &filter, corridor, &count, 256);
    ASSERT_TRUE(dtStatusSucceed(status));
    EXPECT_NE(corridor[count - 1], onRoof) << "nothing climbs the 16 m tower";
}

INSTANTIATE_TEST_SUITE_P(AgentProfiles, SampleLevelTest, ::testing::Values("human", "small"));

} // namespace
} // namespace cairn::bake
