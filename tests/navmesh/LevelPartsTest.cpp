// Level files as objects with materials: OBJ objects and groups and their `usemtl` names (with or without a
// material library), glTF nodes and materials, and the split into one part per object and area.

#include "GltfTestModel.h"
#include "cairn/navmesh/LevelMesh.h"
#include "common/TempFiles.h"

#include <cstring>
#include <gtest/gtest.h>
#include <set>
#include <tiny_gltf.h>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{

class LevelPartsTest : public ::testing::Test
{
protected:
    std::string Write(const std::string& inName, const std::string& inText)
    {
        return mFiles.Write(inName, inText);
    }
    cairn::test::TempFiles mFiles;
};

// Two objects; the first has two materials. Vertices are shared by the whole file, as OBJ has them
const char* cTwoObjects = "v 0 0 0\nv 4 0 0\nv 4 0 4\nv 0 0 4\nv 8 0 0\nv 8 0 4\n"
                          "o Floor\nusemtl road\nf 1 4 3\nf 1 3 2\nusemtl grass\nf 2 3 6\n"
                          "o Ramp\nusemtl road\nf 2 6 5\n";

TEST_F(LevelPartsTest, ObjObjectsAndMaterialsWithoutALibrary)
{
    // No mtllib line at all, and no .mtl file: the names still come through
    for (const std::string& header : {std::string(), std::string("mtllib missing.mtl\n")})
    {
        Result<IndexedMesh> loaded = LoadObjMesh(Write("objects.obj", header + cTwoObjects));
        ASSERT_TRUE(loaded) << loaded.GetError().mMessage;
        const IndexedMesh& mesh = loaded.Value();
        ASSERT_EQ(mesh.mTriangles.size(), 4u);
        ASSERT_EQ(mesh.mObjects.size(), 2u);
        EXPECT_EQ(mesh.mObjects[0].mName, "Floor");
        EXPECT_EQ(mesh.mObjects[0].mFirstTriangle, 0u);
        EXPECT_EQ(mesh.mObjects[0].mNumTriangles, 3u);
        EXPECT_EQ(mesh.mObjects[1].mName, "Ramp");
        EXPECT_EQ(mesh.mObjects[1].mFirstTriangle, 3u);
        EXPECT_EQ(mesh.mObjects[1].mNumTriangles, 1u);
        EXPECT_EQ(mesh.GetMaterialName(0), "road");
        EXPECT_EQ(mesh.GetMaterialName(1), "road");
        EXPECT_EQ(mesh.GetMaterialName(2), "grass");
        EXPECT_EQ(mesh.GetMaterialName(3), "road");
    }
}

TEST_F(LevelPartsTest, IndentedLinesAreCheckedAndNamedToo)
{
    // tinyobjloader reads indented lines: the loader's own checks must see them as well
    Result<IndexedMesh> loaded =
        LoadObjMesh(Write("indented.obj", "v 0 0 0\nv 1 0 0\nv 1 0 1\n  usemtl road\n\tf 1 2 3\n"));
    ASSERT_TRUE(loaded) << loaded.GetError().mMessage;
    EXPECT_EQ(loaded.Value().GetMaterialName(0), "road");
    Result<IndexedMesh> bad =
        LoadObjMesh(Write("indented-bad.obj", "v 0 0 0\n  v 1.2.3 0 0\nv 1 0 1\nf 1 2 3\n"));
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.GetError().mMessage.find(":2:"), std::string::npos) << bad.GetError().mMessage;
}

TEST_F(LevelPartsTest, TrianglesWithoutAMaterialHaveNone)
{
    Result<IndexedMesh> loaded = LoadObjMesh(Write("plain.obj", "v 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 2 3\n"));
    ASSERT_TRUE(loaded) << loaded.GetError().mMessage;
    EXPECT_EQ(loaded.Value().GetMaterialName(0), "");
    ASSERT_EQ(loaded.Value().mObjects.size(), 1u); // The file's unnamed default object
    EXPECT_EQ(loaded.Value().mObjects[0].mNumTriangles, 1u);
}

TEST_F(LevelPartsTest, ErrorLinesStayTheFilesWhenALibraryLineIsAdded)
{
    // A material before any library makes the loader put a line of its own first; the line numbers of
    // errors must still be the file's. Line 5 counts back past the first vertex
    Result<IndexedMesh> loaded = LoadObjMesh(Write("bad-face.obj", "v 0 0 0\nv 1 0 0\nv 1 0 1\n"
                                                                   "usemtl road\nf -9 1 2\n"));
    ASSERT_FALSE(loaded);
    EXPECT_EQ(loaded.GetError().mCode, ErrorCode::ParseError);
    EXPECT_NE(loaded.GetError().mMessage.find("bad-face.obj:5:"), std::string::npos)
        << loaded.GetError().mMessage;
}

TEST_F(LevelPartsTest, PartsPerObjectAndArea)
{
    const IndexedMesh mesh = LoadObjMesh(Write("parts.obj", cTwoObjects)).Value();
    AreaMapping areas;
    areas.mMaterialAreas = {{"road", 1}};
    areas.mDefaultArea = 7; // grass is not named: the default
    const std::vector<LevelPart> parts = SplitIntoParts(mesh, areas).Value();
    ASSERT_EQ(parts.size(), 3u);
    EXPECT_EQ(parts[0].mName, "Floor");
    EXPECT_EQ(parts[0].mArea, 1);
    EXPECT_EQ(parts[0].mMesh.mTriangles.size(), 2u);
    EXPECT_EQ(parts[0].mMesh.mVertices.size(), 4u); // Only the vertices its triangles use
    EXPECT_EQ(parts[1].mName, "Floor");
    EXPECT_EQ(parts[1].mArea, 7);
    EXPECT_EQ(parts[1].mMesh.mTriangles.size(), 1u);
    EXPECT_EQ(parts[1].mMesh.mVertices.size(), 3u);
    EXPECT_EQ(parts[2].mName, "Ramp");
    EXPECT_EQ(parts[2].mArea, 1);
    // The parts together are the mesh's triangles, at the same places
    std::multiset<std::array<float, 9>> original, split;
    auto add = [](std::multiset<std::array<float, 9>>& ioSet, const IndexedMesh& inMesh)
    {
        for (const std::array<uint32_t, 3>& t : inMesh.mTriangles)
        {
            std::array<float, 9> corners;
            for (size_t k = 0; k < 3; ++k)
                for (int axis = 0; axis < 3; ++axis)
                    corners[k * 3 + size_t(axis)] = inMesh.mVertices[t[k]][axis];
            ioSet.insert(corners);
        }
    };
    add(original, mesh);
    for (const LevelPart& part : parts)
        add(split, part.mMesh);
    EXPECT_EQ(original, split);
}

TEST_F(LevelPartsTest, AreaMappingRejectsIdsAboveTheLimit)
{
    AreaMapping areas;
    EXPECT_TRUE(areas.Validate().IsOk());
    areas.mMaterialAreas["lava"] = cMaxAreaId + 1;
    EXPECT_FALSE(areas.Validate().IsOk());
    areas.mMaterialAreas["lava"] = cMaxAreaId;
    areas.mDefaultArea = 200;
    EXPECT_FALSE(areas.Validate().IsOk());
}

/// Two nodes instancing one two-triangle mesh whose primitives use materials "road" and an unnamed one.
tinygltf::Model TwoNodeModel()
{
    tinygltf::Model model = SquareModel(4.0f);
    // Accessors 2 and 3: the first and the second triangle of the square's indices
    for (size_t firstIndex : {0, 3})
    {
        tinygltf::Accessor triangle = model.accessors[1];
        triangle.byteOffset = firstIndex * sizeof(uint16_t);
        triangle.count = 3;
        model.accessors.push_back(triangle);
    }
    tinygltf::Material road, unnamed;
    road.name = "road";
    model.materials = {road, unnamed};
    tinygltf::Mesh mesh;
    for (int p = 0; p < 2; ++p)
    {
        tinygltf::Primitive primitive;
        primitive.attributes["POSITION"] = 0;
        primitive.indices = 2 + p;
        primitive.material = p;
        primitive.mode = TINYGLTF_MODE_TRIANGLES;
        mesh.primitives.push_back(primitive);
    }
    model.meshes.push_back(mesh);
    tinygltf::Node first, second;
    first.mesh = 0;
    first.name = "Bridge";
    second.mesh = 0;
    second.translation = {10, 0, 0};
    model.nodes = {first, second};
    tinygltf::Scene scene;
    scene.nodes = {0, 1};
    model.scenes.push_back(scene);
    model.defaultScene = 0;
    return model;
}

TEST_F(LevelPartsTest, GltfNodesAreObjectsWithTheirMaterials)
{
    const std::string path = Write("nodes.gltf", "");
    tinygltf::TinyGLTF writer;
    const tinygltf::Model model = TwoNodeModel();
    ASSERT_TRUE(writer.WriteGltfSceneToFile(&model, path, true, true, true, false));
    Result<IndexedMesh> loaded = LoadGltfMesh(path);
    ASSERT_TRUE(loaded) << loaded.GetError().mMessage;
    const IndexedMesh& mesh = loaded.Value();
    ASSERT_EQ(mesh.mTriangles.size(), 4u);
    ASSERT_EQ(mesh.mObjects.size(), 2u);
    EXPECT_EQ(mesh.mObjects[0].mName, "Bridge");
    EXPECT_EQ(mesh.mObjects[1].mName, "nodes[1]"); // Unnamed: named by its element
    EXPECT_EQ(mesh.mObjects[1].mFirstTriangle, 2u);
    EXPECT_EQ(mesh.GetMaterialName(0), "road");
    EXPECT_EQ(mesh.GetMaterialName(1), "materials[1]");
    EXPECT_EQ(mesh.GetMaterialName(2), "road");

    // A primitive naming a material that does not exist is an error naming it
    tinygltf::Model broken = TwoNodeModel();
    broken.meshes[0].primitives[1].material = 5;
    ASSERT_TRUE(writer.WriteGltfSceneToFile(&broken, path, true, true, true, false));
    Result<IndexedMesh> bad = LoadGltfMesh(path);
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.GetError().mMessage.find("meshes[0].primitives[1]"), std::string::npos)
        << bad.GetError().mMessage;
}

// A mesh built by hand (not by a loader) may hold indices past its arrays: splitting it or taking triangles
// out of it is an error that names them, where it used to read past the arrays
TEST_F(LevelPartsTest, IndicesPastTheArraysAreErrors)
{
    IndexedMesh mesh;
    mesh.mVertices = {Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(1, 0, 0)};
    mesh.mTriangles = {{0, 1, 2}};
    EXPECT_TRUE(mesh.Validate());
    ASSERT_TRUE(SplitIntoParts(mesh, AreaMapping{}));

    IndexedMesh longObject = mesh;
    longObject.mObjects = {{"floor", 0, 50'000'000}};
    // And one whose end wraps past 2^32 into range
    IndexedMesh wrappingObject = mesh;
    wrappingObject.mObjects = {{"floor", 0xffffffffu, 2}};
    IndexedMesh farVertex = mesh;
    farVertex.mTriangles.push_back({0, 1, 400'000'000});
    for (const IndexedMesh* bad : {&longObject, &wrappingObject, &farVertex})
    {
        EXPECT_EQ(bad->Validate().GetError().mCode, ErrorCode::InvalidArgument);
        const Result<std::vector<LevelPart>> parts = SplitIntoParts(*bad, AreaMapping{});
        ASSERT_FALSE(parts);
        EXPECT_EQ(parts.GetError().mCode, ErrorCode::InvalidArgument);
        EXPECT_NE(parts.GetError().mMessage.find("level mesh:"), std::string::npos)
            << parts.GetError().mMessage;
    }

    const uint32_t pastTheTriangles[] = {40'000'000};
    EXPECT_EQ(mesh.ExtractTriangles(pastTheTriangles).GetError().mCode, ErrorCode::InvalidArgument);
    const uint32_t withAFarVertex[] = {1};
    EXPECT_EQ(farVertex.ExtractTriangles(withAFarVertex).GetError().mCode, ErrorCode::InvalidArgument);
    const uint32_t first[] = {0};
    EXPECT_EQ(farVertex.ExtractTriangles(first).Value().mVertices.size(), 3u);
}

} // namespace
} // namespace cairn::navmesh::test
