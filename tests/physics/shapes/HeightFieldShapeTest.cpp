#include "cairn/physics/shapes/HeightFieldShape.h"

#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <gtest/gtest.h>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <tuple>

using namespace cairn;
using namespace cairn::physics;

namespace
{

std::shared_ptr<const HeightFieldShape> MakeField(uint32_t inCountX, uint32_t inCountZ, float inCellSize,
                                                  const std::vector<float>& inHeights)
{
    auto result = HeightFieldShape::Create(inCountX, inCountZ, inCellSize, inHeights);
    EXPECT_TRUE(result.IsOk()) << (result.IsOk() ? "" : result.GetError().mMessage);
    return result.IsOk() ? result.Value() : nullptr;
}

std::vector<Triangle> AllTriangles(const Shape& inShape)
{
    std::vector<Triangle> triangles;
    inShape.VisitTriangles(AABB(Vec3::Constant(-1e6f), Vec3::Constant(1e6f)),
                           [&](const Triangle& t) { triangles.push_back(t); });
    return triangles;
}

/// A random terrain with a few holes.
std::shared_ptr<const HeightFieldShape> RandomField(std::mt19937& ioRng, uint32_t inCountX, uint32_t inCountZ,
                                                    float inCellSize)
{
    std::uniform_real_distribution<float> height(-2.0f, 2.0f);
    std::uniform_int_distribution<int> hole(0, 30);
    std::vector<float> heights(inCountX * inCountZ);
    for (float& h : heights)
        h = hole(ioRng) == 0 ? HeightFieldShape::cHole : height(ioRng);
    return MakeField(inCountX, inCountZ, inCellSize, heights);
}

} // namespace

TEST(HeightFieldShapeTest, RejectsBadInput)
{
    const std::vector<float> four(4, 0.0f);
    EXPECT_EQ(HeightFieldShape::Create(1, 4, 1.0f, four).GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_EQ(HeightFieldShape::Create(2, 3, 1.0f, four).GetError().mCode, ErrorCode::InvalidArgument);
    // Counts whose product overflows 32 bits must not wrap around to the span's size
    EXPECT_EQ(HeightFieldShape::Create(65536, 65536, 1.0f, four).GetError().mCode,
              ErrorCode::InvalidArgument);
    // Over 2^31 cells their triangles' sub-shape ids would not fit 32 bits: refused by the count alone
    const auto tooMany = HeightFieldShape::Create(65537, 32770, 1.0f, four);
    ASSERT_FALSE(tooMany.IsOk());
    EXPECT_EQ(tooMany.GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_NE(tooMany.GetError().mMessage.find("2^31 cells"), std::string::npos)
        << tooMany.GetError().mMessage;
    EXPECT_EQ(HeightFieldShape::Create(2, 2, 0.0f, four).GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_EQ(HeightFieldShape::Create(2, 2, -1.0f, four).GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_EQ(HeightFieldShape::Create(2, 2, 1e-30f, four).GetError().mCode, ErrorCode::DegenerateShape)
        << "cells too small for the ray walk's indices";
    EXPECT_EQ(HeightFieldShape::Create(2, 2, std::numeric_limits<float>::quiet_NaN(), four).GetError().mCode,
              ErrorCode::InvalidArgument);
    std::vector<float> infinite = four;
    infinite[2] = std::numeric_limits<float>::infinity();
    EXPECT_EQ(HeightFieldShape::Create(2, 2, 1.0f, infinite).GetError().mCode, ErrorCode::InvalidArgument);
    const std::vector<float> holes(4, HeightFieldShape::cHole);
    EXPECT_EQ(HeightFieldShape::Create(2, 2, 1.0f, holes).GetError().mCode, ErrorCode::DegenerateShape);
    // One hole in a single-cell field removes the only cell
    std::vector<float> oneHole = four;
    oneHole[3] = HeightFieldShape::cHole;
    auto error = HeightFieldShape::Create(2, 2, 1.0f, oneHole);
    ASSERT_FALSE(error.IsOk());
    EXPECT_FALSE(error.GetError().mMessage.empty());

    const auto field = MakeField(2, 2, 1.0f, four);
    ASSERT_NE(field, nullptr);
    EXPECT_EQ(field->GetMassProperties(1000.0f).mMass, 0.0f);
    EXPECT_EQ(field->GetType(), ShapeType::HeightField);
}

TEST(HeightFieldShapeTest, SamplesAndCellsOutsideTheGridReadAsHoles)
{
    const std::vector<float> heights = {0, 1, 2, 3, 4, 5}; // 3 x 2 samples, 2 x 1 cells
    auto field = HeightFieldShape::Create(3, 2, 1.0f, heights).Value();
    EXPECT_EQ(field->GetHeight(2, 1), 5.0f);
    EXPECT_TRUE(std::isnan(field->GetHeight(3, 0))) << "one past the row";
    EXPECT_TRUE(std::isnan(field->GetHeight(0, 2))) << "one past the last row";
    EXPECT_TRUE(std::isnan(field->GetHeight(UINT32_MAX, UINT32_MAX)));
    EXPECT_EQ(field->GetCellActiveEdges(2, 0), 0u) << "the samples' last column has no cell";
    EXPECT_EQ(field->GetCellActiveEdges(0, 1), 0u);
    EXPECT_EQ(field->GetCellActiveEdges(UINT32_MAX, 0), 0u) << "x + 1 wraps in 32 bits";
    EXPECT_EQ(field->GetCellActiveEdges(0, UINT32_MAX), 0u);
}

TEST(HeightFieldShapeTest, TrianglesLayoutAndIds)
{
    // 3 x 2 samples, cell size 2: 2 cells, 4 triangles facing up
    const auto field = MakeField(3, 2, 2.0f, {0, 1, 2, 3, 4, 5});
    ASSERT_NE(field, nullptr);
    EXPECT_TRUE(field->GetLocalBounds().mMin.isApprox(Vec3(0, 0, 0)));
    EXPECT_TRUE(field->GetLocalBounds().mMax.isApprox(Vec3(4, 5, 2)));
    const std::vector<Triangle> triangles = AllTriangles(*field);
    ASSERT_EQ(triangles.size(), 4u);
    std::set<SubShapeID> ids;
    for (const Triangle& t : triangles)
    {
        ids.insert(t.mSubShape);
        const Vec3 n = (t.mV[1] - t.mV[0]).cross(t.mV[2] - t.mV[0]);
        EXPECT_GT(n.y(), 0.0f);
        // Every vertex is a sample: height = x / 2 + 3 z / 2
        for (const Vec3& v : t.mV)
            EXPECT_FLOAT_EQ(v.y(), v.x() / 2.0f + 1.5f * v.z());
        // The cell index in the id matches the vertices' x range
        const float cellX = float((t.mSubShape / 2) % 2) * 2.0f;
        for (const Vec3& v : t.mV)
            EXPECT_TRUE(v.x() == cellX || v.x() == cellX + 2.0f);
    }
    EXPECT_EQ(ids, (std::set<SubShapeID>{0, 1, 2, 3}));
}

TEST(HeightFieldShapeTest, RayCastRamp)
{
    // Ramp rising along x with slope 0.5
    std::vector<float> heights;
    for (int z = 0; z < 8; ++z)
        for (int x = 0; x < 10; ++x)
            heights.push_back(0.5f * float(x));
    const auto field = MakeField(10, 8, 1.0f, heights);
    ASSERT_NE(field, nullptr);
    const Vec3 rampNormal = Vec3(-0.5f, 1.0f, 0.0f).normalized();

    RayHit down;
    ASSERT_TRUE(field->CastRay({Vec3(3.3f, 10, 2.7f), Vec3(0, -20, 0)}, down));
    EXPECT_NEAR(down.mFraction, (10.0f - 1.65f) / 20.0f, 1e-5f);
    EXPECT_TRUE(down.mNormal.isApprox(rampNormal, 1e-5f));
    EXPECT_EQ(down.mSubShape / 2, 3u + 2u * 9u); // Cell (3, 2)

    // A long shallow ray along +x at height 2 meets the ramp where 0.5 x = 2
    RayHit along;
    ASSERT_TRUE(field->CastRay({Vec3(-5, 2, 4.5f), Vec3(20, 0, 0.1f)}, along));
    EXPECT_NEAR(along.mFraction, 9.0f / 20.0f, 1e-5f);
    EXPECT_TRUE(along.mNormal.isApprox(rampNormal, 1e-5f));

    // From below (two-sided): the normal faces the ray
    RayHit up;
    ASSERT_TRUE(field->CastRay({Vec3(5.5f, -3, 5.5f), Vec3(0, 10, 0)}, up));
    EXPECT_NEAR(up.mFraction, (2.75f + 3.0f) / 10.0f, 1e-5f);
    EXPECT_TRUE(up.mNormal.isApprox(-rampNormal, 1e-5f));

    RayHit miss;
    EXPECT_FALSE(field->CastRay({Vec3(3, 10, 3), Vec3(0, -5, 0)}, miss));   // Too short
    EXPECT_FALSE(field->CastRay({Vec3(-3, 10, 3), Vec3(0, -20, 0)}, miss)); // Beside the field
    EXPECT_FALSE(field->CastRay({Vec3(-5, 6, 3), Vec3(20, 0, 0)}, miss));   // Above everything
    EXPECT_FALSE(field->CastRay({Vec3(3, 10, 3), Vec3::Zero()}, miss));
}

TEST(HeightFieldShapeTest, RayCastMatchesBruteForce)
{
    std::mt19937 rng(5);
    const auto field = RandomField(rng, 23, 17, 0.75f);
    ASSERT_NE(field, nullptr);
    const std::vector<Triangle> triangles = AllTriangles(*field);

    std::uniform_real_distribution<float> x(-3.0f, 20.0f), y(-4.0f, 4.0f), z(-3.0f, 15.0f), len(0.0f, 1.0f);
    int hits = 0;
    for (int r = 0; r < 1000; ++r)
    {
        const Vec3 from(x(rng), y(rng), z(rng));
        // Mix of long grazing rays and short steep ones
        const Vec3 to =
            r % 2 == 0 ? Vec3(x(rng), y(rng), z(rng)) : from + Vec3(len(rng), -8.0f * len(rng), len(rng));
        const RayCast ray{from, to - from};
        float expected = cLargeFloat;
        for (const Triangle& t : triangles)
            expected = std::min(expected, ShapeHelpers::RayTriangleFraction(ray, t.mV[0], t.mV[1], t.mV[2]));
        RayHit hit;
        const bool result = field->CastRay(ray, hit);
        ASSERT_EQ(result, expected <= 1.0f) << "ray " << r;
        if (result)
        {
            ++hits;
            EXPECT_NEAR(hit.mFraction, expected, 1e-5f) << "ray " << r;
        }
    }
    EXPECT_GT(hits, 200);
}

TEST(HeightFieldShapeTest, VisitTrianglesSupersetAndHoles)
{
    std::mt19937 rng(11);
    const auto field = RandomField(rng, 20, 14, 0.5f);
    ASSERT_NE(field, nullptr);
    const std::vector<Triangle> all = AllTriangles(*field);
    for (const Triangle& t : all)
        for (const Vec3& v : t.mV)
            EXPECT_FALSE(std::isnan(v.y())) << "a triangle touches a hole";
    size_t solidCells = 0;
    for (uint32_t cz = 0; cz + 1 < field->GetSampleCountZ(); ++cz)
        for (uint32_t cx = 0; cx + 1 < field->GetSampleCountX(); ++cx)
            if (!std::isnan(field->GetHeight(cx, cz)) && !std::isnan(field->GetHeight(cx + 1, cz)) &&
                !std::isnan(field->GetHeight(cx, cz + 1)) && !std::isnan(field->GetHeight(cx + 1, cz + 1)))
                ++solidCells;
    EXPECT_EQ(all.size(), 2 * solidCells);
    EXPECT_LT(solidCells, size_t(19 * 13)); // The seed must produce holes for the test to mean something

    std::uniform_real_distribution<float> coord(-1.0f, 11.0f), height(-2.5f, 2.5f), size(0.0f, 1.5f);
    for (int b = 0; b < 300; ++b)
    {
        const AABB box = AABB::FromCenterExtent(Vec3(coord(rng), height(rng), coord(rng)),
                                                Vec3(size(rng), size(rng), size(rng)));
        std::set<SubShapeID> visited;
        field->VisitTriangles(box, [&](const Triangle& t) { visited.insert(t.mSubShape); });
        for (const Triangle& t : all)
            if (ShapeHelpers::TriangleBounds(t.mV[0], t.mV[1], t.mV[2]).Overlaps(box))
            {
                EXPECT_TRUE(visited.contains(t.mSubShape)) << "missed " << t.mSubShape << " in box " << b;
            }
        // Only the cells under the box are visited
        EXPECT_LE(visited.size(), size_t(2 * (std::ceil(box.Size().x() / 0.5f) + 1) *
                                         (std::ceil(box.Size().z() / 0.5f) + 1)));
    }
}

/// Active edges of inField's triangles lying along x = inX: 2 of them in the fields below.
int ActiveEdgesAlongX(const HeightFieldShape& inField, float inX)
{
    int activeCount = 0, count = 0;
    for (const Triangle& t : AllTriangles(inField))
        for (int e = 0; e < 3; ++e)
            if (t.mV[e].x() == inX && t.mV[(e + 1) % 3].x() == inX)
            {
                ++count;
                activeCount += (t.mActiveEdges & (1u << e)) != 0 ? 1 : 0;
            }
    EXPECT_EQ(count, 2);
    return activeCount;
}

TEST(HeightFieldShapeTest, InternalEdges)
{
    // Flat 2 x 2 cells: the edges on the border are active, every other edge is inactive
    const auto flat = MakeField(3, 3, 1.0f, std::vector<float>(9, 1.0f));
    ASSERT_NE(flat, nullptr);
    int active = 0;
    for (const Triangle& t : AllTriangles(*flat))
        for (int e = 0; e < 3; ++e)
        {
            const Vec3& a = t.mV[e];
            const Vec3& b = t.mV[(e + 1) % 3];
            const bool border = (a.x() == b.x() && (a.x() == 0.0f || a.x() == 2.0f)) ||
                                (a.z() == b.z() && (a.z() == 0.0f || a.z() == 2.0f));
            EXPECT_EQ((t.mActiveEdges & (1u << e)) != 0, border)
                << "triangle " << t.mSubShape << " edge " << e;
            active += (t.mActiveEdges & (1u << e)) != 0 ? 1 : 0;
        }
    EXPECT_EQ(active, 8);

    // A 90-degree convex ridge along z at x = 1 keeps its edge active; the mirrored valley (concave) does not
    const auto ridge = MakeField(3, 2, 1.0f, {0, 1, 0, 0, 1, 0});
    ASSERT_NE(ridge, nullptr);
    EXPECT_EQ(ActiveEdgesAlongX(*ridge, 1.0f), 2);
    const auto valley = MakeField(3, 2, 1.0f, {1, 0, 1, 1, 0, 1});
    ASSERT_NE(valley, nullptr);
    EXPECT_EQ(ActiveEdgesAlongX(*valley, 1.0f), 0);

    // Next to a hole the edge has no neighbour: active
    const float h = HeightFieldShape::cHole;
    const auto holed = MakeField(4, 2, 1.0f, {0, 0, h, 0, 0, 0, 0, 0});
    ASSERT_NE(holed, nullptr);
    const std::vector<Triangle> triangles = AllTriangles(*holed);
    ASSERT_EQ(triangles.size(), 2u); // Cells 1 and 2 touch the hole sample (2, 0): only cell 0 is left
    for (const Triangle& t : triangles)
        for (int e = 0; e < 3; ++e)
            if (t.mV[e].x() == 1.0f && t.mV[(e + 1) % 3].x() == 1.0f)
            {
                EXPECT_NE(t.mActiveEdges & (1u << e), 0);
            }
}

TEST(HeightFieldShapeTest, InternalEdgesAtTheWorldsScale)
{
    // Cells of 200 km with heights of 200 km: the triangles' normals (edge cross products, not normalised)
    // have squared lengths whose product overflows a float. The flat joint must still be internal, the ridge
    // active and the valley internal
    constexpr float cell = 2.0e5f;
    const auto flat = MakeField(3, 2, cell, std::vector<float>(6, cell));
    ASSERT_NE(flat, nullptr);
    EXPECT_EQ(ActiveEdgesAlongX(*flat, cell), 0);
    const auto ridge = MakeField(3, 2, cell, {0, cell, 0, 0, cell, 0});
    ASSERT_NE(ridge, nullptr);
    EXPECT_EQ(ActiveEdgesAlongX(*ridge, cell), 2);
    const auto valley = MakeField(3, 2, cell, {cell, 0, cell, cell, 0, cell});
    ASSERT_NE(valley, nullptr);
    EXPECT_EQ(ActiveEdgesAlongX(*valley, cell), 0);
}

TEST(HeightFieldShapeTest, EdgeFlagsEqualThoseOfTheSameTrianglesAsAMesh)
{
    // The field works its flags out per cell from the grid at creation; a mesh of the same triangles finds
    // its neighbours by shared vertices: two ways to the same answer, holes and borders included
    std::mt19937 rng(17);
    for (int trial = 0; trial < 4; ++trial)
    {
        const float cell = 0.7f;
        const auto field = RandomField(rng, 12, 9, cell);
        ASSERT_NE(field, nullptr);
        const std::vector<Triangle> fieldTriangles = AllTriangles(*field);
        ASSERT_GT(fieldTriangles.size(), 50u);
        std::vector<Vec3> vertices;
        std::map<std::pair<long, long>, uint32_t> vertexOfSample;
        auto vertexOf = [&](const Vec3& inV)
        {
            const std::pair<long, long> sample{std::lround(inV.x() / cell), std::lround(inV.z() / cell)};
            auto [it, added] = vertexOfSample.try_emplace(sample, uint32_t(vertices.size()));
            if (added) vertices.push_back(inV);
            return it->second;
        };
        std::vector<std::array<uint32_t, 3>> indices;
        for (const Triangle& t : fieldTriangles)
            indices.push_back({vertexOf(t.mV[0]), vertexOf(t.mV[1]), vertexOf(t.mV[2])});
        auto mesh = TriangleMeshShape::Create(vertices, indices);
        ASSERT_TRUE(mesh.IsOk()) << mesh.GetError().mMessage;

        // Each edge of each triangle, named by its vertices: whether it is active
        using EdgeKey = std::tuple<uint32_t, uint32_t, uint32_t, uint32_t, uint32_t>;
        auto edgeFlags = [&](const std::vector<Triangle>& inTriangles)
        {
            std::map<EdgeKey, bool> flags;
            for (const Triangle& t : inTriangles)
            {
                std::array<uint32_t, 3> corners{vertexOf(t.mV[0]), vertexOf(t.mV[1]), vertexOf(t.mV[2])};
                std::array<uint32_t, 3> sorted = corners;
                std::sort(sorted.begin(), sorted.end());
                for (int e = 0; e < 3; ++e)
                    flags[{sorted[0], sorted[1], sorted[2], corners[e], corners[(e + 1) % 3]}] =
                        (t.mActiveEdges & (1u << e)) != 0;
            }
            return flags;
        };
        const std::map<EdgeKey, bool> fromField = edgeFlags(fieldTriangles);
        const std::map<EdgeKey, bool> fromMesh = edgeFlags(AllTriangles(*mesh.Value()));
        ASSERT_EQ(fromField.size(), fromMesh.size());
        int active = 0;
        for (const auto& [edge, isActive] : fromField)
        {
            const auto it = fromMesh.find(edge);
            ASSERT_NE(it, fromMesh.end());
            EXPECT_EQ(isActive, it->second) << "trial " << trial;
            active += isActive ? 1 : 0;
        }
        EXPECT_GT(active, 0) << "borders and holes are active";
        EXPECT_LT(active, int(fromField.size())) << "the concave joints of a random terrain are internal";
    }
}
