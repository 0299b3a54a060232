// The demo world's navmesh keeps a standing agent out of its props: at every point of every polygon's detail
// surface (the height agents stand at, Detour's getPolyHeight), the demo's chest probe (Agents.h) overlaps no
// static body but the terrain. Built for both of the demo's agent profiles over one world tile of the default
// seed: world tile (1, 0), 64 m, 25 navmesh tiles a profile, from its terrain and props (the huts' walls
// among them) as the demo streams them in.
//
// Without huts, that tile holds the stack that once put a demo agent inside a prop: a crate on a platform on
// a slope, each step under the agent's climb, inside one polygon whose detail surface Recast sampled as a
// ramp running 1.2 m under the crate's top. The tile builder now resamples such polygons finely (BuiltTile's
// mResampledPolygons); without that, 17 points of this scan (at 5 cm) failed.

#include "Agents.h"
#include "WorldGenerator.h"
#include "WorldNavTile.h"
#include "cairn/navmesh/GeometryCollector.h"
#include "cairn/navmesh/TileBuilder.h"
#include "cairn/physics/PhysicsSystem.h"
#include "common/MakePhysicsSystem.h"

#include <DetourNavMesh.h>
#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>
#include <string>

namespace cairn::demo
{
namespace
{
using namespace cairn::physics;

/// The sample spacing on the detail surface: a fraction of the smallest prop
constexpr float cSpacing = 0.1f;

struct ScanResult
{
    int mPoints = 0;
    int mInside = 0;
    std::string mFirstInside;
};

/// Tests the chest probe over a point lattice of each detail triangle of inTile.
void ScanTile(const dtMeshTile& inTile, const PhysicsSystem& inPhysics, const std::vector<BodyID>& inTerrain,
              ScanResult& ioResult)
{
    QueryFilter statics;
    statics.mObjectLayers = ObjectLayerMask(1) << Layers::cStatic;
    std::vector<BodyID> bodies;
    for (int p = 0; p < inTile.header->polyCount; ++p)
    {
        const dtPoly& poly = inTile.polys[p];
        const dtPolyDetail& detail = inTile.detailMeshes[p];
        for (int t = 0; t < detail.triCount; ++t)
        {
            const unsigned char* tri = &inTile.detailTris[(detail.triBase + t) * 4];
            const float* v[3];
            for (int j = 0; j < 3; ++j)
                v[j] = tri[j] < poly.vertCount
                           ? &inTile.verts[poly.verts[tri[j]] * 3]
                           : &inTile.detailVerts[(detail.vertBase + tri[j] - poly.vertCount) * 3];
            const float area =
                (v[1][0] - v[0][0]) * (v[2][2] - v[0][2]) - (v[2][0] - v[0][0]) * (v[1][2] - v[0][2]);
            if (std::abs(area) < 1e-9f) continue;
            const float minX = std::min({v[0][0], v[1][0], v[2][0]}),
                        maxX = std::max({v[0][0], v[1][0], v[2][0]});
            const float minZ = std::min({v[0][2], v[1][2], v[2][2]}),
                        maxZ = std::max({v[0][2], v[1][2], v[2][2]});
            for (float x = std::ceil(minX / cSpacing) * cSpacing; x <= maxX; x += cSpacing)
                for (float z = std::ceil(minZ / cSpacing) * cSpacing; z <= maxZ; z += cSpacing)
                {
                    const float a = ((v[1][0] - x) * (v[2][2] - z) - (v[2][0] - x) * (v[1][2] - z)) / area;
                    const float b = ((v[2][0] - x) * (v[0][2] - z) - (v[0][0] - x) * (v[2][2] - z)) / area;
                    const float c = 1.0f - a - b;
                    if (a < 0.0f || b < 0.0f || c < 0.0f) continue;
                    const Vec3 chest(x, a * v[0][1] + b * v[1][1] + c * v[2][1] + cChestProbeHeight, z);
                    ++ioResult.mPoints;
                    bodies.clear();
                    ASSERT_TRUE(
                        inPhysics.GetWorldQuery().CollideSphere(chest, cChestProbeRadius, bodies, statics));
                    std::erase_if(
                        bodies, [&](const BodyID& inBody)
                        { return std::find(inTerrain.begin(), inTerrain.end(), inBody) != inTerrain.end(); });
                    if (bodies.empty()) continue;
                    if (ioResult.mInside++ == 0)
                        ioResult.mFirstInside = "polygon " + std::to_string(p) + ", chest at (" +
                                                std::to_string(x) + ", " + std::to_string(chest.y()) + ", " +
                                                std::to_string(z) + ")";
                }
        }
    }
}

/// Builds and scans both profiles' navmesh over world tile (1, 0) of inWorld; returns the polygons resampled.
int ScanWorldTile(const WorldSettings& inWorld)
{
    PhysicsSettings settings;
    settings.mMaxBodies = 4096;
    const std::unique_ptr<PhysicsSystem> physics = cairn::test::MakePhysicsSystem(settings);
    BodyInterface& bodies = physics->GetBodyInterface();
    const WorldGenerator generator(inWorld);
    const WorldTile worldTile{1, 0};
    TileContent content = generator.GenerateTile(worldTile, false);
    const std::vector<BodyID> terrain{
        bodies.CreateAndAddBody(content.mTerrain, Activation::DontActivate).Value()};
    for (const BodyCreationSettings& prop : content.mProps) // The huts' walls among them
        EXPECT_TRUE(bodies.CreateAndAddBody(prop, Activation::DontActivate));

    navmesh::AgentProfile large;
    large.mRadius = 1.5f;
    const navmesh::GeometryCollector collector(physics->GetBodyManager(), physics->GetBroadPhase());
    int resampled = 0;
    for (const navmesh::AgentProfile& profile : {navmesh::AgentProfile(), large})
    {
        SCOPED_TRACE("agent radius " + std::to_string(profile.mRadius));
        const navmesh::TileGrid grid(0.0f, 0.0f, profile.mTileSize, -50.0f, 100.0f);
        const float worldTileSize = generator.GetSettings().mTileSize;
        const int navTilesAcross = int(std::lround(worldTileSize / profile.mTileSize));
        ScanResult scan;
        for (int z = 0; z < navTilesAcross; ++z)
            for (int x = 0; x < navTilesAcross; ++x)
            {
                const navmesh::TileCoord tile{worldTile.mX * navTilesAcross + x,
                                              worldTile.mZ * navTilesAcross + z};
                Result<navmesh::BuiltTile> built = BuildWorldNavTile(collector, profile, grid, tile);
                if (!built)
                {
                    ADD_FAILURE() << built.GetError().mMessage;
                    continue;
                }
                EXPECT_EQ(built.Value().mRoughPolygons, 0) << "tile " << tile.mX << ", " << tile.mZ;
                EXPECT_LE(built.Value().mMaxDetailError, profile.mMaxClimb);
                resampled += built.Value().mResampledPolygons;
                if (!built.Value().mData) continue;

                dtNavMeshParams params{};
                params.tileWidth = params.tileHeight = profile.mTileSize;
                params.maxTiles = 1;
                params.maxPolys = 1 << 16;
                dtNavMesh mesh;
                // Detour reads the data in place and leaves it to BuiltTile (no DT_TILE_FREE_DATA)
                if (!dtStatusSucceed(mesh.init(&params)) ||
                    !dtStatusSucceed(
                        mesh.addTile(built.Value().mData.get(), built.Value().mDataSize, 0, 0, nullptr)))
                {
                    ADD_FAILURE() << "Detour refused tile " << tile.mX << ", " << tile.mZ;
                    continue;
                }
                ScanTile(*static_cast<const dtNavMesh&>(mesh).getTile(0), *physics, terrain, scan);
            }
        EXPECT_GT(scan.mPoints, 100000); // The tile is mostly walkable: the scan covered it
        EXPECT_EQ(scan.mInside, 0) << "first: " << scan.mFirstInside;
    }
    return resampled;
}

TEST(NavMeshClearOfPropsTest, NoPointOfTheDemoWorldsNavMeshPutsAnAgentsChestInAProp)
{
    ScanWorldTile(WorldSettings{}); // The demo's default world, with its huts
}

TEST(NavMeshClearOfPropsTest, NoPointPutsAnAgentsChestInTheStackThatOnceDid)
{
    // Without huts the tile's props are those the stack was found among (huts are placed first)
    WorldSettings world;
    world.mBuildingsPerTile = 0;
    // The stack's tile took the resampling path
    EXPECT_GT(ScanWorldTile(world), 0);
}

} // namespace
} // namespace cairn::demo
