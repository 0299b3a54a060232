// Navmesh files from disk that Detour would trust: the file's header asking for more than its bytes hold, the
// navmesh parameters Detour's own test lets through, and tile contents that passed the old checks yet made
// Detour's queries read NULL or search for ever. Each is refused by LoadNavMeshFile with a message naming the
// file and the place; the fuzzer's corpus (tests/fuzz/corpus/fuzz_navmesh_file) holds the inputs it found.

#include "cairn/navmesh/NavMeshFile.h"
#include "cairn/navmesh/TileBuilder.h"
#include "common/TempFiles.h"

#include <DetourNavMesh.h>
#include <cmath>
#include <cstring>
#include <gtest/gtest.h>
#include <limits>

namespace cairn::navmesh::test
{
using namespace cairn::physics;
namespace
{
using cairn::test::ReadBytes;
using cairn::test::TempFiles;

// The file layout of NavMeshFile.h: the set header (magic, version, tile count, parameters), then per tile
// its reference and size before its data
constexpr size_t cParamsAt = 12;
constexpr size_t cFirstTileAt = 12 + sizeof(dtNavMeshParams) + sizeof(dtTileRef) + sizeof(int32_t);
constexpr size_t cVertsAt = (sizeof(dtMeshHeader) + 3) & ~size_t(3);

class NavMeshFileHostileTest : public ::testing::Test
{
protected:
    /// A navmesh file of one flat tile, as the baker writes it.
    void SetUp() override
    {
        const TileGrid grid(0, 0, AgentProfile{}.mTileSize, -1, 10);
        TileGeometry geometry;
        geometry.AddTriangle(Vec3(0, 0, 0), Vec3(0, 0, 10), Vec3(10, 0, 0), cDefaultArea);
        geometry.AddTriangle(Vec3(10, 0, 0), Vec3(0, 0, 10), Vec3(10, 0, 10), cDefaultArea);
        Result<BuiltTile> built = BuildTile(AgentProfile{}, grid, {0, 0}, geometry);
        ASSERT_TRUE(built.IsOk());
        NavMeshFileContents contents;
        contents.mParams = MakeNavMeshParams(grid, 16).Value();
        contents.mTiles.push_back(
            {{0, 0}, {built.Value().mData.get(), built.Value().mData.get() + built.Value().mDataSize}});
        mPath = mFiles.Path("good.navmesh");
        ASSERT_TRUE(SaveNavMeshFile(mPath, contents).IsOk());
        mBytes = ReadBytes(mPath);
        ASSERT_TRUE(LoadNavMeshFile(mPath).IsOk());
    }

    dtMeshHeader TileHeader() const
    {
        dtMeshHeader header;
        std::memcpy(&header, mBytes.data() + cFirstTileAt, sizeof(header));
        return header;
    }

    template <class T> static void Put(std::vector<unsigned char>& ioBytes, size_t inAt, const T& inValue)
    {
        std::memcpy(ioBytes.data() + inAt, &inValue, sizeof(T));
    }

    /// Writes inBytes as a file and expects LoadNavMeshFile to refuse it with a message holding inWhat.
    void ExpectRefused(const std::vector<unsigned char>& inBytes, const std::string& inWhat)
    {
        const std::string path = mFiles.Write("bad.navmesh", std::string(inBytes.begin(), inBytes.end()));
        Result<NavMeshFileContents> loaded = LoadNavMeshFile(path);
        ASSERT_FALSE(loaded.IsOk()) << "expected: " << inWhat;
        EXPECT_EQ(loaded.GetError().mCode, ErrorCode::ParseError);
        EXPECT_NE(loaded.GetError().mMessage.find(path), std::string::npos) << loaded.GetError().mMessage;
        EXPECT_NE(loaded.GetError().mMessage.find(inWhat), std::string::npos) << loaded.GetError().mMessage;
    }

    TempFiles mFiles;
    std::string mPath;
    std::vector<unsigned char> mBytes;
};

TEST_F(NavMeshFileHostileTest, ParametersDetourWouldLetThroughAreRefused)
{
    auto withParams = [&](auto&& inChange)
    {
        std::vector<unsigned char> bytes = mBytes;
        dtNavMeshParams params;
        std::memcpy(&params, bytes.data() + cParamsAt, sizeof(params));
        inChange(params);
        Put(bytes, cParamsAt, params);
        return bytes;
    };
    // 2^30 tiles: Detour's salt-bit test wraps around and passes, then it allocates a record per tile
    ExpectRefused(withParams([](dtNavMeshParams& p) { p.maxTiles = 1 << 30; }), "max tiles");
    ExpectRefused(withParams([](dtNavMeshParams& p) { p.maxTiles = 0; }), "max tiles");
    ExpectRefused(withParams([](dtNavMeshParams& p) { p.maxPolys = -1; }), "max polygons");
    ExpectRefused(withParams([](dtNavMeshParams& p) { p.maxTiles = 1 << 12, p.maxPolys = 1 << 14; }),
                  "bits of salt");
    ExpectRefused(withParams([](dtNavMeshParams& p) { p.orig[0] = std::numeric_limits<float>::quiet_NaN(); }),
                  "origin");
    ExpectRefused(withParams([](dtNavMeshParams& p) { p.tileWidth = 0.0f; }), "tile size");
    // Tiles a hair wide: a search box of a few metres covered billions of tile slots (the fuzzer's timeout)
    ExpectRefused(withParams([](dtNavMeshParams& p) { p.tileWidth = 1.0e-6f; }), "tile size");
    ExpectRefused(withParams([](dtNavMeshParams& p) { p.tileHeight = 0.2f; }), "tile size");
    ExpectRefused(
        withParams([](dtNavMeshParams& p) { p.tileHeight = std::numeric_limits<float>::infinity(); }),
        "tile size");
}

TEST_F(NavMeshFileHostileTest, CountsAndSizesBeyondTheFilesBytesAreRefusedBeforeAnyAllocation)
{
    // A 40-byte file that asks for a million tiles: refused from its size, not after allocating for them
    std::vector<unsigned char> header(mBytes.begin(), mBytes.begin() + 12 + sizeof(dtNavMeshParams));
    Put(header, 8, int32_t(1 << 20));
    dtNavMeshParams params;
    std::memcpy(&params, header.data() + cParamsAt, sizeof(params));
    params.maxTiles = 1 << 20;
    params.maxPolys = 4;
    Put(header, cParamsAt, params);
    ExpectRefused(header, "more than the file's bytes hold");

    std::vector<unsigned char> bigTile = mBytes;
    Put(bigTile, cFirstTileAt - sizeof(int32_t), int32_t(1 << 27)); // The tile's data size
    ExpectRefused(bigTile, "remain");
}

TEST_F(NavMeshFileHostileTest, TilesAfterTheCountedOnesAreRefusedNotDropped)
{
    std::vector<unsigned char> bytes = mBytes;
    bytes.insert(bytes.end(), mBytes.begin() + 40, mBytes.end()); // The tile once more, uncounted
    ExpectRefused(bytes, "bytes follow the 1 tiles");
    std::vector<unsigned char> twice = bytes;
    Put(twice, 8, int32_t(2)); // Counted now: the same place twice
    Put(twice, cParamsAt + offsetof(dtNavMeshParams, maxTiles), int32_t(16));
    ExpectRefused(twice, "a second tile at (0, 0)");
}

TEST_F(NavMeshFileHostileTest, CoordinatesThatMakeDetoursPathCostsNaNAreRefused)
{
    // A NaN vertex made findPath's costs NaN, which never compare greater: its search reopened nodes for ever
    std::vector<unsigned char> nanVertex = mBytes;
    Put(nanVertex, cFirstTileAt + cVertsAt + sizeof(float), std::numeric_limits<float>::quiet_NaN());
    ExpectRefused(nanVertex, "vertex 0 is not finite");
    std::vector<unsigned char> hugeVertex = mBytes;
    Put(hugeVertex, cFirstTileAt + cVertsAt, 3.0e38f); // Finite, but infinite once subtracted from -3e38
    ExpectRefused(hugeVertex, "vertex 0 is not finite or out of range");

    dtMeshHeader header = TileHeader();
    header.bmax[1] = std::numeric_limits<float>::infinity();
    std::vector<unsigned char> badBounds = mBytes;
    Put(badBounds, cFirstTileAt, header);
    ExpectRefused(badBounds, "its bounds are not finite");
}

TEST_F(NavMeshFileHostileTest, APolygonWithoutBoundaryDetailTrianglesIsRefused)
{
    // Detour's closest point on a polygon read NULL for a polygon whose detail mesh had no triangle (one
    // zeroed byte the fuzzer found), or none with an edge flagged as boundary
    const dtMeshHeader header = TileHeader();
    ASSERT_GT(header.polyCount, 0);
    size_t detailsAt = cVertsAt + size_t(header.vertCount) * 12;
    detailsAt += ((size_t(header.polyCount) * sizeof(dtPoly) + 3) & ~size_t(3));
    detailsAt += ((size_t(header.maxLinkCount) * sizeof(dtLink) + 3) & ~size_t(3));
    dtPolyDetail detail;
    std::memcpy(&detail, mBytes.data() + cFirstTileAt + detailsAt, sizeof(detail));
    ASSERT_GT(detail.triCount, 0);

    std::vector<unsigned char> noTriangles = mBytes;
    dtPolyDetail empty = detail;
    empty.triCount = 0;
    Put(noTriangles, cFirstTileAt + detailsAt, empty);
    ExpectRefused(noTriangles, "the detail mesh of polygon 0 has no triangle on its boundary");

    std::vector<unsigned char> noBoundary = mBytes;
    const size_t detailTrisAt = detailsAt +
                                ((size_t(header.detailMeshCount) * sizeof(dtPolyDetail) + 3) & ~size_t(3)) +
                                size_t(header.detailVertCount) * 12;
    for (int t = 0; t < detail.triCount; ++t)
        noBoundary[cFirstTileAt + detailTrisAt + (size_t(detail.triBase) + size_t(t)) * 4 + 3] = 0;
    ExpectRefused(noBoundary, "the detail mesh of polygon 0 has no triangle on its boundary");
}

TEST_F(NavMeshFileHostileTest, LinksDetoursRaycastWouldWalkForEverAreRefused)
{
    // Detour's raycast follows the links from polygon to polygon with no bound: a polygon that names itself
    // as a neighbour (one changed byte, found by the fuzzer) kept it on that polygon for ever
    const dtMeshHeader header = TileHeader();
    ASSERT_GT(header.polyCount, 0);
    const size_t polysAt = cFirstTileAt + cVertsAt + size_t(header.vertCount) * 12;
    dtPoly poly;
    std::memcpy(&poly, mBytes.data() + polysAt, sizeof(poly));
    poly.neis[0] = 1; // Polygon 0's first edge leads to polygon 0
    std::vector<unsigned char> selfLinked = mBytes;
    Put(selfLinked, polysAt, poly);
    ExpectRefused(selfLinked, "polygon 0 is its own neighbour");
}

} // namespace
} // namespace cairn::navmesh::test
