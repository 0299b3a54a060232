// Level files a content pipeline could hand the baker that must be refused, fast and with a message naming
// the file and the place or limit, rather than crash, hang, exhaust memory or read files they should not:
// glTF nested past the stack, node graphs that multiply, images (never decoded), buffers from outside the
// level's folder, OBJ lines that tinyobjloader would read as something else. LevelLoadLimits configures the
// bounds, and the errors name them.

#include "cairn/navmesh/LevelMesh.h"
#include "common/TempFiles.h"

#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <string>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{
using cairn::test::TempFiles;

// A 10 m square's four positions (float VEC3) then its six unsigned short indices, base64
constexpr const char* cSquareBuffer =
    "data:application/octet-stream;base64,"
    "AACgwAAAAAAAAKDAAACgQAAAAAAAAKDAAACgQAAAAAAAAKBAAACgwAAAAAAAAKBAAAACAAEAAAADAAIA";
constexpr int cSquareBufferBytes = 60;

/// A glTF of the square, its buffer at inBufferUri, with inNodes and inScenes (JSON arrays) and inExtra
/// (more top-level members, with their leading comma).
std::string GltfText(const std::string& inNodes, const std::string& inScenes,
                     const std::string& inBufferUri = cSquareBuffer, const std::string& inExtra = "")
{
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": )" + inScenes + R"(, "nodes": )" + inNodes +
           R"(, "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
               "buffers": [{"uri": ")" +
           inBufferUri + R"(", "byteLength": )" + std::to_string(cSquareBufferBytes) + R"(}],
               "bufferViews": [{"buffer": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
               "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                              "min": [-5, 0, -5], "max": [5, 0, 5]},
                             {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}])" +
           inExtra + "}";
}

const std::string cOneNode = R"([{"mesh": 0}])";
const std::string cOneScene = R"([{"nodes": [0]}])";

class LevelFileHostileTest : public ::testing::Test
{
protected:
    /// Expects inPath to be refused with ParseError, a message naming the file and holding inWhat.
    static void ExpectRefused(const std::string& inPath, const std::string& inWhat,
                              const LevelLoadLimits& inLimits = {})
    {
        Result<IndexedMesh> loaded = LoadLevelMesh(inPath, inLimits);
        ASSERT_FALSE(loaded.IsOk()) << "expected: " << inWhat;
        EXPECT_EQ(loaded.GetError().mCode, ErrorCode::ParseError) << loaded.GetError().mMessage;
        EXPECT_NE(loaded.GetError().mMessage.find(inPath), std::string::npos) << loaded.GetError().mMessage;
        EXPECT_NE(loaded.GetError().mMessage.find(inWhat), std::string::npos) << loaded.GetError().mMessage;
    }

    TempFiles mFiles;
};

TEST_F(LevelFileHostileTest, TheTestModelLoads)
{
    Result<IndexedMesh> loaded = LoadLevelMesh(mFiles.Write("square.gltf", GltfText(cOneNode, cOneScene)));
    ASSERT_TRUE(loaded.IsOk()) << loaded.GetError().mMessage;
    EXPECT_EQ(loaded.Value().mTriangles.size(), 2u);
}

TEST_F(LevelFileHostileTest, JsonNestedPastTheLimitIsRefusedBeforeTinygltfRecursesIntoIt)
{
    // 100,000 arrays deep in a node's extras (a 200 KB file) overflowed the stack in tinygltf's conversion
    const std::string deep = std::string(100000, '[') + std::string(100000, ']');
    const std::string nodes = R"([{"mesh": 0, "extras": {"deep": )" + deep + "}}]";
    ExpectRefused(mFiles.Write("deep.gltf", GltfText(nodes, cOneScene)), "LevelLoadLimits::mMaxNesting");
    // Brackets inside strings are text, not nesting
    const std::string quoted = R"([{"mesh": 0, "name": ")" + std::string(1000, '[') + R"("}])";
    EXPECT_TRUE(LoadLevelMesh(mFiles.Write("quoted.gltf", GltfText(quoted, cOneScene))).IsOk());
}

TEST_F(LevelFileHostileTest, ANodeGraphThatSharesNodesIsRefusedNotMultiplied)
{
    // 40 levels of two nodes, each parent of both nodes below it: 2^40 instances of the mesh from a 2 KB file
    std::string nodes = "[";
    for (int level = 0; level < 40; ++level)
        for (int k = 0; k < 2; ++k)
        {
            const std::string children = level + 1 < 40
                                             ? R"(, "children": [)" + std::to_string(2 * level + 2) + ", " +
                                                   std::to_string(2 * level + 3) + "]"
                                             : "";
            nodes += std::string(level + k > 0 ? ", " : "") + R"({"mesh": 0)" + children + "}";
        }
    nodes += "]";
    ExpectRefused(mFiles.Write("diamond.gltf", GltfText(nodes, cOneScene)), "is reached a second time");
    // A cycle without a scene has no root: no triangles, and no endless walk
    const std::string cycle = R"([{"mesh": 0, "children": [1]}, {"mesh": 0, "children": [0]}])";
    ExpectRefused(mFiles.Write("cycle.gltf", GltfText(cycle, "[]")), "no triangles");
    // Deep but a tree: refused at the depth limit, which names itself
    std::string chain = "[";
    for (int i = 0; i < 100; ++i)
        chain +=
            std::string(i > 0 ? ", " : "") + R"({"mesh": 0, "children": [)" + std::to_string(i + 1) + "]}";
    chain += R"(, {"mesh": 0}])";
    ExpectRefused(mFiles.Write("chain.gltf", GltfText(chain, cOneScene)), "LevelLoadLimits::mMaxNodeDepth");
    LevelLoadLimits deeper;
    deeper.mMaxNodeDepth = 200;
    EXPECT_TRUE(LoadLevelMesh(mFiles.Path("chain.gltf"), deeper).IsOk());
}

TEST_F(LevelFileHostileTest, TrianglesAndVerticesPastTheLimitsAreRefused)
{
    const std::string path = mFiles.Write("square.gltf", GltfText(cOneNode, cOneScene));
    LevelLoadLimits limits;
    limits.mMaxTriangles = 1;
    ExpectRefused(path, "LevelLoadLimits::mMaxTriangles", limits);
    limits = {};
    limits.mMaxVertices = 3;
    ExpectRefused(path, "LevelLoadLimits::mMaxVertices", limits);
    limits = {};
    limits.mMaxFileBytes = 100;
    ExpectRefused(path, "LevelLoadLimits::mMaxFileBytes", limits);
}

TEST_F(LevelFileHostileTest, ImagesAreNeverDecoded)
{
    // Bytes no image decoder takes: tinygltf's decoder failed the whole load on them (and decoded a 16384^2
    // PNG for 27 s); the navmesh has no use for images
    const std::string images = R"(, "images": [{"uri": "data:image/png;base64,AAECAwQFBgcICQ=="}])";
    Result<IndexedMesh> loaded =
        LoadLevelMesh(mFiles.Write("image.gltf", GltfText(cOneNode, cOneScene, cSquareBuffer, images)));
    EXPECT_TRUE(loaded.IsOk()) << loaded.GetError().mMessage;
}

TEST_F(LevelFileHostileTest, BuffersComeOnlyFromTheLevelsFolder)
{
    // The buffer's bytes as a file, beside the level and outside its folder
    const std::string bytes(cSquareBufferBytes, '\0');
    std::filesystem::create_directories(mFiles.Path("level"));
    mFiles.Write("outside.bin", bytes);
    mFiles.Write("level/inside.bin", bytes);
    const std::string outside =
        mFiles.Write("level/outside.gltf", GltfText(cOneNode, cOneScene, "../outside.bin"));
    ExpectRefused(outside, "outside the level's folder");
    // Nothing of the file outside leaks into the message, not even its size (looked for with the test's
    // folder taken out: the process id in its name may hold the same digits)
    std::string message = LoadLevelMesh(outside).GetError().mMessage;
    for (std::size_t at; (at = message.find(mFiles.Path(""))) != std::string::npos;)
        message.erase(at, mFiles.Path("").size());
    EXPECT_EQ(message.find(std::to_string(cSquareBufferBytes)), std::string::npos) << message;
    ExpectRefused(
        mFiles.Write("level/absolute.gltf", GltfText(cOneNode, cOneScene, mFiles.Path("outside.bin"))),
        "outside the level's folder");
    std::filesystem::create_symlink(mFiles.Path("outside.bin"), mFiles.Path("level/link.bin"));
    ExpectRefused(mFiles.Write("level/link.gltf", GltfText(cOneNode, cOneScene, "link.bin")),
                  "outside the level's folder");
    // A file that does not exist outside reads the same as one that does
    ExpectRefused(mFiles.Write("level/missing.gltf", GltfText(cOneNode, cOneScene, "../missing.bin")),
                  "outside the level's folder");

    // Inside the folder is fine; and outside when the limits allow it
    EXPECT_TRUE(
        LoadLevelMesh(mFiles.Write("level/inside.gltf", GltfText(cOneNode, cOneScene, "inside.bin"))).IsOk());
    LevelLoadLimits anywhere;
    anywhere.mAllowFilesOutsideFolder = true;
    EXPECT_TRUE(LoadLevelMesh(outside, anywhere).IsOk());
}

TEST_F(LevelFileHostileTest, ABufferThatIsAFolderIsAnErrorNotAnAbort)
{
    // tinygltf read "." as a file and threw from the allocation its size asked for: the process aborted
    ExpectRefused(mFiles.Write("dot.gltf", GltfText(cOneNode, cOneScene, ".")), "not a readable file");
}

TEST_F(LevelFileHostileTest, ObjLinesEndedByCarriageReturnsAreCheckedAsLines)
{
    // tinyobjloader ends lines at a lone CR: the checks read the file as one line, and 'x' loaded as 0
    ExpectRefused(mFiles.Write("cr.obj", "v 0 0 0\rv x 0 0\rv 1 0 1\rf 1 2 3\r"),
                  "cr.obj:2: 'x' is not a finite number");
    ExpectRefused(mFiles.Write("cr-dots.obj", "v 0 0 0\rv 1.2.3 0 0\rv 1 0 1\rf 1 2 3\r"), "'1.2.3'");
    ExpectRefused(mFiles.Write("cr-nan.obj", "v 0 0 0\rv nan 0 0\rv 1 0 1\rf 1 2 3\r"), "'nan'");
    Result<IndexedMesh> good =
        LoadLevelMesh(mFiles.Write("cr-good.obj", "v 0 0 0\rv 1 0 0\rv 1 0 1\rf 1 2 3\r"));
    ASSERT_TRUE(good.IsOk()) << good.GetError().mMessage;
    EXPECT_EQ(good.Value().mTriangles.size(), 1u);
}

TEST_F(LevelFileHostileTest, ObjFacesTinyobjloaderWouldReadAsOthersAreRefused)
{
    const std::string vertices = "v 0 0 0\nv 1 0 0\nv 1 0 1\n";
    // An index past an int wrapped into some vertex
    ExpectRefused(mFiles.Write("huge.obj", vertices + "f 1 2 99999999999999999999\n"),
                  "huge.obj:4: '99999999999999999999' is not a face corner");
    ExpectRefused(mFiles.Write("zero.obj", vertices + "f 0 1 2\n"), "'0' is not a face corner");
    ExpectRefused(mFiles.Write("junk.obj", vertices + "f 1 2 3x\n"), "'3x' is not a face corner");
    // A face cut short (the end of a truncated file) was dropped without a word
    ExpectRefused(mFiles.Write("truncated.obj", vertices + "f 1 2 3\nf 1 2"),
                  "truncated.obj:5: a face needs 3 corners");
    // Slashes with texture and normal indices, empty or not, and negative indices are OBJ
    EXPECT_TRUE(LoadLevelMesh(mFiles.Write("slashes.obj", vertices + "vt 0 0\nvn 0 1 0\nf 1/1/1 2//1 -1/1\n"))
                    .IsOk());
}

TEST_F(LevelFileHostileTest, AFileThatCannotBeReadIsAnIOErrorNotAnEmptyLevel)
{
    // A folder, whatever its name
    for (const std::string name : {"folder.obj", "folder.gltf", "folder.glb"})
    {
        std::filesystem::create_directories(mFiles.Path(name));
        Result<IndexedMesh> loaded = LoadLevelMesh(mFiles.Path(name));
        ASSERT_FALSE(loaded.IsOk()) << name;
        EXPECT_EQ(loaded.GetError().mCode, ErrorCode::IOError) << loaded.GetError().mMessage;
    }
    // A file this user may not read was "no triangles" (needs a user that permissions stop: not root)
    const std::string locked = mFiles.Write("locked.obj", "v 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 2 3\n");
    std::filesystem::permissions(locked, std::filesystem::perms::none);
    if (std::ifstream(locked).good()) GTEST_SKIP() << "this user reads files without permission (root)";
    Result<IndexedMesh> loaded = LoadLevelMesh(locked);
    ASSERT_FALSE(loaded.IsOk());
    EXPECT_EQ(loaded.GetError().mCode, ErrorCode::IOError);
    EXPECT_NE(loaded.GetError().mMessage.find("cannot be read"), std::string::npos)
        << loaded.GetError().mMessage;
}

TEST_F(LevelFileHostileTest, ExtensionsAreReadInAnyCase)
{
    const std::string obj = "v 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 2 3\n";
    for (const std::string name : {"a.obj", "b.OBJ", "c.Obj"})
        EXPECT_TRUE(LoadLevelMesh(mFiles.Write(name, obj)).IsOk()) << name;
    EXPECT_TRUE(LoadLevelMesh(mFiles.Write("d.GLTF", GltfText(cOneNode, cOneScene))).IsOk());
}

} // namespace
} // namespace cairn::navmesh::test
