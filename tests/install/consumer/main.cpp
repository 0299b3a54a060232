// A program outside Cairn's tree that finds the installed package and links cairn::physics and
// cairn::navmesh: a dropped sphere falls under gravity, and a navmesh tile is built from a floor body in the
// physics world. Prints the height after one second and the tile's polygons so the test can check the
// libraries really ran.
#include <cairn/navmesh/GeometryCollector.h>
#include <cairn/navmesh/TileBuilder.h>
#include <cairn/physics/PhysicsSystem.h>
#include <cairn/physics/shapes/BoxShape.h>
#include <cairn/physics/shapes/SphereShape.h>
#include <cstdio>
#include <memory>

int main()
{
    cairn::physics::Result<std::unique_ptr<cairn::physics::PhysicsSystem>> created = cairn::physics::PhysicsSystem::Create();
    if (!created)
    {
        std::fprintf(stderr, "PhysicsSystem::Create: %s\n", created.GetError().mMessage.c_str());
        return 1;
    }
    cairn::physics::PhysicsSystem& system = *created.Value();
    cairn::physics::BodyCreationSettings settings;
    settings.mShape = cairn::physics::SphereShape::Create(1.0f).Value();
    settings.mPosition = cairn::physics::Vec3(0, 10, 0);
    const cairn::physics::BodyID id =
        system.GetBodyInterface().CreateAndAddBody(settings, cairn::physics::Activation::Activate).Value();
    for (int i = 0; i < 60; ++i)
        (void)system.Update(1.0f / 60.0f);
    std::printf("height after 1 s: %.2f\n", system.GetBodyInterface().GetPosition(id).Value().y());

    // A static floor far from the sphere, and the navmesh tile over it
    cairn::physics::BodyCreationSettings floor;
    floor.mShape = cairn::physics::BoxShape::Create(cairn::physics::Vec3(20, 0.5f, 20)).Value();
    floor.mPosition = cairn::physics::Vec3(100, -0.5f, 100);
    floor.mMotionType = cairn::physics::MotionType::Static;
    floor.mObjectLayer = cairn::physics::Layers::cStatic;
    (void)system.GetBodyInterface().CreateAndAddBody(floor, cairn::physics::Activation::DontActivate);
    const cairn::navmesh::AgentProfile profile;
    const cairn::navmesh::TileGrid grid(0, 0, profile.mTileSize, -5, 5);
    const cairn::navmesh::TileCoord tile{8, 8}; // x and z in [102.4, 115.2]: on the floor
    const cairn::physics::AABB box =
        grid.GetTileBoundsWithBorder(tile, float(profile.GetBorderCells()) * profile.mCellSize);
    const cairn::navmesh::GeometryCollector collector(system.GetBodyManager(), system.GetBroadPhase());
    std::vector<cairn::physics::BodyID> bodies;
    cairn::navmesh::TileGeometry geometry;
    cairn::navmesh::CollectStats stats;
    collector.FindBodies(box, {}, bodies);
    collector.CollectTriangles(box, {}, bodies, geometry, stats);
    const auto built = cairn::navmesh::BuildTile(profile, grid, tile, geometry);
    std::printf("navmesh tile polygons: %d\n", built ? built.Value().mNumPolygons : -1);
    return 0;
}
