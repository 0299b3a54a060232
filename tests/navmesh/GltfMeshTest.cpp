// glTF level meshes: nodes' transforms applied, the same walkable tiles as the same geometry from OBJ, and
// malformed files named by file and element.

#include "GltfTestModel.h"
#include "cairn/navmesh/LevelMesh.h"
#include "cairn/navmesh/TileBuilder.h"
#include "common/TempFiles.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <tiny_gltf.h>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

std::string TempPath(const std::string& inName)
{
    static const cairn::test::TempFiles files; // A folder of this process's own, removed at exit
    return files.Path(inName);
}

/// A 20 m square floor (two triangles, unsigned short indices) in a node moved by inTranslation.
tinygltf::Model FloorModel(const std::array<double, 3>& inTranslation)
{
    tinygltf::Model model = SquareModel(20.0f);
    tinygltf::Primitive primitive;
    primitive.attributes["POSITION"] = 0;
    primitive.indices = 1;
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Mesh mesh;
    mesh.primitives.push_back(primitive);
    model.meshes.push_back(mesh);
    tinygltf::Node node;
    node.mesh = 0;
    node.translation = {inTranslation[0], inTranslation[1], inTranslation[2]};
    model.nodes.push_back(node);
    tinygltf::Scene scene;
    scene.nodes = {0};
    model.scenes.push_back(scene);
    model.defaultScene = 0;
    return model;
}

void Write(const tinygltf::Model& inModel, const std::string& inPath, bool inBinary)
{
    tinygltf::TinyGLTF writer;
    ASSERT_TRUE(writer.WriteGltfSceneToFile(&inModel, inPath, true, true, true, inBinary));
}

TEST(GltfMeshTest, NodesArePlacedAndTheFloorIsWalkable)
{
    for (bool binary : {false, true})
    {
        const std::string path = TempPath(binary ? "floor.glb" : "floor.gltf");
        Write(FloorModel({2, 1, 3}), path, binary);
        Result<IndexedMesh> mesh = LoadLevelMesh(path);
        ASSERT_TRUE(mesh) << mesh.GetError().mMessage;
        ASSERT_EQ(mesh.Value().mVertices.size(), 4u);
        ASSERT_EQ(mesh.Value().mTriangles.size(), 2u);
        EXPECT_EQ(mesh.Value().mVertices[2], Vec3(22, 1, 23)); // Moved by the node
        // As walkable as the same floor from an OBJ file
        const std::string obj = TempPath("floor.obj");
        std::ofstream(obj) << "v 2 1 3\nv 2 1 23\nv 22 1 23\nv 22 1 3\nf 1 2 3\nf 1 3 4\n";
        const AgentProfile profile;
        const TileGrid grid(0, 0, profile.mTileSize, 0, 5);
        Result<BuiltTile> fromGltf = BuildTile(profile, grid, {0, 0}, mesh.Value().ToTileGeometry());
        Result<BuiltTile> fromObj =
            BuildTile(profile, grid, {0, 0}, LoadLevelMesh(obj).Value().ToTileGeometry());
        ASSERT_TRUE(fromGltf && fromObj);
        EXPECT_GT(fromGltf.Value().mNumPolygons, 0);
        EXPECT_EQ(fromGltf.Value().mNumPolygons, fromObj.Value().mNumPolygons);
        EXPECT_EQ(fromGltf.Value().mDataSize, fromObj.Value().mDataSize);
        std::filesystem::remove(path);
        std::filesystem::remove(obj);
    }
}

TEST(GltfMeshTest, MalformedFilesNameTheFileAndElement)
{
    const std::string path = TempPath("bad.gltf");
    std::ofstream(path) << "{ this is not json";
    Result<IndexedMesh> notJson = LoadGltfMesh(path);
    ASSERT_FALSE(notJson);
    EXPECT_EQ(notJson.GetError().mCode, ErrorCode::ParseError);
    EXPECT_NE(notJson.GetError().mMessage.find(path), std::string::npos);

    // A model written out must be refused with a message holding inExpected
    auto expectRefused = [&](const tinygltf::Model& inModel, const std::string& inExpected)
    {
        Write(inModel, path, false);
        const Result<IndexedMesh> loaded = LoadGltfMesh(path);
        ASSERT_FALSE(loaded) << inExpected;
        EXPECT_NE(loaded.GetError().mMessage.find(inExpected), std::string::npos)
            << loaded.GetError().mMessage;
    };
    tinygltf::Model badIndex = FloorModel({0, 0, 0});
    reinterpret_cast<uint16_t*>(badIndex.buffers[0].data.data() + 48)[2] = 9; // Beyond the 4 vertices
    expectRefused(badIndex, "meshes[0].primitives[0]");
    tinygltf::Model badAccessor = FloorModel({0, 0, 0});
    badAccessor.accessors[0].count = 400; // Reads beyond its buffer
    expectRefused(badAccessor, "accessors[0]");

    // Sizes whose sums or products wrap around in 64 bits: they passed the bounds check and read far outside
    // the buffer (2^62 elements), or 2 KB before it (an offset 2,048 short of 2^64, over 171 elements whose
    // end wraps round to 4 bytes into the view)
    tinygltf::Model hugeCount = FloorModel({0, 0, 0});
    hugeCount.accessors[0].count = size_t(1) << 62;
    expectRefused(hugeCount, "accessors[0]: reads beyond its buffer");
    tinygltf::Model wrappingOffset = FloorModel({0, 0, 0});
    wrappingOffset.accessors[0].byteOffset = ~size_t(0) - 2047;
    wrappingOffset.accessors[0].count = 171;
    expectRefused(wrappingOffset, "accessors[0]: reads beyond its buffer");
    tinygltf::Model badView = FloorModel({0, 0, 0});
    badView.bufferViews[1].byteOffset = ~size_t(0) - 7; // The view's own end wraps round
    expectRefused(badView, "buffer view beyond its buffer");

    EXPECT_EQ(LoadLevelMesh(TempPath("level.fbx")).GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_EQ(LoadGltfMesh(TempPath("missing.glb")).GetError().mCode, ErrorCode::IOError);
    std::filesystem::remove(path);
}

} // namespace
} // namespace cairn::navmesh::test
