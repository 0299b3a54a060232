#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <limits>
#include <random>
#include <set>

using namespace cairn;
using namespace cairn::physics;

namespace
{

using Indices = std::array<uint32_t, 3>;

std::shared_ptr<const TriangleMeshShape> MakeMesh(const std::vector<Vec3>& inVertices,
                                                  const std::vector<Indices>& inTriangles)
{
    auto result = TriangleMeshShape::Create(inVertices, inTriangles);
    EXPECT_TRUE(result.IsOk()) << (result.IsOk() ? "" : result.GetError().mMessage);
    return result.IsOk() ? result.Value() : nullptr;
}

/// An n x n grid of quads in the XZ plane (y = 0), 2 triangles per quad, facing +Y.
void FlatGrid(int inQuads, std::vector<Vec3>& outVertices, std::vector<Indices>& outTriangles)
{
    const uint32_t n = uint32_t(inQuads) + 1;
    for (uint32_t z = 0; z < n; ++z)
        for (uint32_t x = 0; x < n; ++x)
            outVertices.push_back(Vec3(float(x), 0.0f, float(z)));
    for (uint32_t z = 0; z + 1 < n; ++z)
        for (uint32_t x = 0; x + 1 < n; ++x)
        {
            const uint32_t i = x + z * n;
            outTriangles.push_back({i, i + n, i + n + 1});
            outTriangles.push_back({i, i + n + 1, i + 1});
        }
}

/// Every triangle of the shape by sub-shape id, from visiting its whole bounds.
std::map<SubShapeID, Triangle> TrianglesByID(const Shape& inShape)
{
    std::map<SubShapeID, Triangle> triangles;
    inShape.VisitTriangles(inShape.GetLocalBounds(), [&](const Triangle& t) { triangles[t.mSubShape] = t; });
    return triangles;
}

/// True when the edge lies on the border of the [0, inSize] x [0, inSize] grid.
bool EdgeOnBorder(const Vec3& inA, const Vec3& inB, float inSize)
{
    auto onBorder = [&](int inAxis, float inValue)
    { return inA[inAxis] == inValue && inB[inAxis] == inValue; };
    return onBorder(0, 0.0f) || onBorder(0, inSize) || onBorder(2, 0.0f) || onBorder(2, inSize);
}

} // namespace

TEST(TriangleMeshShapeTest, RejectsBadInput)
{
    const std::vector<Vec3> vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};
    const std::vector<Indices> triangle = {{0, 2, 1}};

    EXPECT_EQ(TriangleMeshShape::Create(vertices, std::vector<Indices>{}).GetError().mCode,
              ErrorCode::DegenerateShape);

    auto outOfRange = TriangleMeshShape::Create(vertices, std::vector<Indices>{{0, 1, 3}});
    ASSERT_FALSE(outOfRange.IsOk());
    EXPECT_EQ(outOfRange.GetError().mCode, ErrorCode::InvalidArgument);
    EXPECT_NE(outOfRange.GetError().mMessage.find("index 3"), std::string::npos);

    std::vector<Vec3> nanVertices = vertices;
    nanVertices[1].z() = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(TriangleMeshShape::Create(nanVertices, triangle).GetError().mCode, ErrorCode::InvalidArgument);
    std::vector<Vec3> infVertices = vertices;
    infVertices[2].x() = -std::numeric_limits<float>::infinity();
    EXPECT_EQ(TriangleMeshShape::Create(infVertices, triangle).GetError().mCode, ErrorCode::InvalidArgument);

    const std::vector<Vec3> collinear = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
    EXPECT_EQ(TriangleMeshShape::Create(collinear, triangle).GetError().mCode, ErrorCode::DegenerateShape);
    EXPECT_EQ(TriangleMeshShape::Create(vertices, std::vector<Indices>{{0, 0, 1}}).GetError().mCode,
              ErrorCode::DegenerateShape);

    // Degenerate triangles among good ones are dropped
    const auto mesh = MakeMesh(vertices, {{0, 0, 1}, {0, 2, 1}, {1, 1, 1}});
    ASSERT_NE(mesh, nullptr);
    EXPECT_EQ(mesh->GetTriangleCount(), 1u);
    EXPECT_EQ(mesh->GetMassProperties(1000.0f).mMass, 0.0f);
    EXPECT_FALSE(mesh->IsConvex());
}

TEST(TriangleMeshShapeTest, RayCastQuad)
{
    // Unit quad at y = 1, facing +Y
    const auto mesh =
        MakeMesh({Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(1, 1, 1), Vec3(0, 1, 1)}, {{0, 2, 1}, {0, 3, 2}});
    ASSERT_NE(mesh, nullptr);

    RayHit down;
    ASSERT_TRUE(mesh->CastRay({Vec3(0.25f, 3, 0.75f), Vec3(0, -4, 0)}, down));
    EXPECT_NEAR(down.mFraction, 0.5f, 1e-6f);
    EXPECT_TRUE(down.mNormal.isApprox(Vec3(0, 1, 0)));
    EXPECT_EQ(down.mSubShape, 1u); // The second input triangle holds (0.25, 0.75)

    RayHit up; // Two-sided: the back face is hit too, with the normal facing the ray
    ASSERT_TRUE(mesh->CastRay({Vec3(0.75f, -1, 0.25f), Vec3(0, 4, 0)}, up));
    EXPECT_NEAR(up.mFraction, 0.5f, 1e-6f);
    EXPECT_TRUE(up.mNormal.isApprox(Vec3(0, -1, 0)));
    EXPECT_EQ(up.mSubShape, 0u);

    RayHit miss;
    EXPECT_FALSE(mesh->CastRay({Vec3(1.5f, 3, 0.5f), Vec3(0, -4, 0)}, miss));
    EXPECT_FALSE(mesh->CastRay({Vec3(0.5f, 3, 0.5f), Vec3(0, -1, 0)}, miss)); // Too short
    EXPECT_FALSE(mesh->CastRay({Vec3(0.5f, 1, 0.5f), Vec3::Zero()}, miss));   // No volume: never inside
    EXPECT_FALSE(mesh->CastRay({Vec3(-1, 1, 0.5f), Vec3(3, 0, 0)}, miss));    // In the plane
    RayHit closer;
    closer.mFraction = 0.4f;
    EXPECT_FALSE(mesh->CastRay({Vec3(0.25f, 3, 0.75f), Vec3(0, -4, 0)}, closer));
    EXPECT_EQ(closer.mFraction, 0.4f);
}

TEST(TriangleMeshShapeTest, BvhRayCastMatchesBruteForce)
{
    std::mt19937 rng(1234);
    std::uniform_real_distribution<float> coord(-10.0f, 10.0f);
    std::uniform_real_distribution<float> offset(-1.0f, 1.0f);
    std::vector<Vec3> vertices;
    std::vector<Indices> triangles;
    for (uint32_t i = 0; i < 600; ++i)
    {
        const Vec3 center(coord(rng), coord(rng), coord(rng));
        for (int v = 0; v < 3; ++v)
            vertices.push_back(center + Vec3(offset(rng), offset(rng), offset(rng)));
        triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
    }
    const auto mesh = MakeMesh(vertices, triangles);
    ASSERT_NE(mesh, nullptr);
    ASSERT_EQ(mesh->GetTriangleCount(), 600u);

    int hits = 0;
    for (int r = 0; r < 1000; ++r)
    {
        const RayCast ray{Vec3(coord(rng), coord(rng), coord(rng)),
                          2.0f * Vec3(coord(rng), coord(rng), coord(rng))};
        float expected = cLargeFloat;
        for (const Indices& t : triangles)
            expected = std::min(expected, ShapeHelpers::RayTriangleFraction(ray, vertices[t[0]],
                                                                            vertices[t[1]], vertices[t[2]]));
        RayHit hit;
        const bool result = mesh->CastRay(ray, hit);
        ASSERT_EQ(result, expected <= 1.0f) << "ray " << r;
        if (!result) continue;
        ++hits;
        EXPECT_EQ(hit.mFraction, expected) << "ray " << r;
        const Indices& t = triangles[hit.mSubShape];
        EXPECT_EQ(ShapeHelpers::RayTriangleFraction(ray, vertices[t[0]], vertices[t[1]], vertices[t[2]]),
                  hit.mFraction);
        EXPECT_NEAR(hit.mNormal.norm(), 1.0f, 1e-5f);
        EXPECT_LE(hit.mNormal.dot(ray.mDirection), 0.0f);
    }
    EXPECT_GT(hits, 100); // The test would be vacuous without hits
}

TEST(TriangleMeshShapeTest, VisitTrianglesIsSupersetOfOverlapping)
{
    std::vector<Vec3> vertices;
    std::vector<Indices> triangles;
    FlatGrid(16, vertices, triangles);
    std::mt19937 rng(99);
    std::uniform_real_distribution<float> height(-0.5f, 0.5f);
    for (Vec3& v : vertices)
        v.y() = height(rng);
    const auto mesh = MakeMesh(vertices, triangles);
    ASSERT_NE(mesh, nullptr);

    std::uniform_real_distribution<float> coord(-2.0f, 18.0f);
    std::uniform_real_distribution<float> size(0.0f, 3.0f);
    for (int b = 0; b < 200; ++b)
    {
        const AABB box = AABB::FromCenterExtent(Vec3(coord(rng), height(rng), coord(rng)),
                                                Vec3(size(rng), size(rng) * 0.2f, size(rng)));
        std::set<SubShapeID> visited;
        mesh->VisitTriangles(box,
                             [&](const Triangle& t)
                             {
                                 EXPECT_TRUE(visited.insert(t.mSubShape).second) << "triangle visited twice";
                                 const Indices& in = triangles[t.mSubShape];
                                 for (int i = 0; i < 3; ++i)
                                     EXPECT_EQ(t.mV[i], vertices[in[i]]);
                             });
        for (SubShapeID i = 0; i < triangles.size(); ++i)
        {
            const Indices& t = triangles[i];
            if (ShapeHelpers::TriangleBounds(vertices[t[0]], vertices[t[1]], vertices[t[2]]).Overlaps(box))
            {
                EXPECT_TRUE(visited.contains(i)) << "missed triangle " << i << " in box " << b;
            }
        }
    }
}

TEST(TriangleMeshShapeTest, FlatGridInternalEdgesInactive)
{
    std::vector<Vec3> vertices;
    std::vector<Indices> triangles;
    FlatGrid(2, vertices, triangles);
    const auto mesh = MakeMesh(vertices, triangles);
    ASSERT_NE(mesh, nullptr);
    const auto all = TrianglesByID(*mesh);
    ASSERT_EQ(all.size(), 8u);
    int active = 0;
    for (const auto& [id, t] : all)
        for (int e = 0; e < 3; ++e)
        {
            const bool isActive = (t.mActiveEdges & (1u << e)) != 0;
            EXPECT_EQ(isActive, EdgeOnBorder(t.mV[e], t.mV[(e + 1) % 3], 2.0f))
                << "triangle " << id << " edge " << e;
            active += isActive ? 1 : 0;
        }
    EXPECT_EQ(active, 8); // 2 border edges per side
}

TEST(TriangleMeshShapeTest, ConvexRidgeActiveConcaveValleyInactive)
{
    // Two quads meeting at 90 degrees along the z axis: a roof ridge (convex, normals up-left and up-right)
    const std::vector<Vec3> ridge = {Vec3(0, 0, 0),   Vec3(0, 0, 1),  Vec3(-1, -1, 0),
                                     Vec3(-1, -1, 1), Vec3(1, -1, 0), Vec3(1, -1, 1)};
    // Left slope (normal (-1, 1, 0)/sqrt2) and right slope (normal (1, 1, 0)/sqrt2), consistently wound
    const std::vector<Indices> roof = {{0, 2, 3}, {0, 3, 1}, {0, 1, 5}, {0, 5, 4}};
    const auto mesh = MakeMesh(ridge, roof);
    ASSERT_NE(mesh, nullptr);
    auto ridgeEdgeActive = [](const std::map<SubShapeID, Triangle>& inAll, bool inExpected)
    {
        int checked = 0;
        for (const auto& [id, t] : inAll)
        {
            const Vec3 n = (t.mV[1] - t.mV[0]).cross(t.mV[2] - t.mV[0]);
            EXPECT_GT(n.y(), 0.0f) << "test mesh must face up";
            for (int e = 0; e < 3; ++e)
            {
                const Vec3& a = t.mV[e];
                const Vec3& b = t.mV[(e + 1) % 3];
                if (a.x() == 0.0f && b.x() == 0.0f && a.y() == 0.0f && b.y() == 0.0f)
                {
                    EXPECT_EQ((t.mActiveEdges & (1u << e)) != 0, inExpected) << "triangle " << id;
                    ++checked;
                }
                // The outer long edges (x = +-1) belong to one triangle only
                if (a.x() == b.x() && a.z() != b.z() && a.x() != 0.0f)
                {
                    EXPECT_NE(t.mActiveEdges & (1u << e), 0) << "outer border edge must be active";
                }
            }
        }
        EXPECT_EQ(checked, 2);
    };
    ridgeEdgeActive(TrianglesByID(*mesh), true);

    // Mirrored upside down (a valley, still facing up): the joint is concave, so the edge is inactive
    std::vector<Vec3> valley = ridge;
    for (Vec3& v : valley)
        v.y() = -v.y();
    // A mirror flips both the normal and the winding, so the same indices still face up
    const auto valleyMesh = MakeMesh(valley, roof);
    ASSERT_NE(valleyMesh, nullptr);
    ridgeEdgeActive(TrianglesByID(*valleyMesh), false);
}

TEST(TriangleMeshShapeTest, CollectTrianglesAtTransform)
{
    const auto mesh = MakeMesh(
        {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(10, 0, 10), Vec3(11, 0, 10), Vec3(10, 0, 11)},
        {{0, 2, 1}, {3, 5, 4}});
    ASSERT_NE(mesh, nullptr);
    Transform transform;
    transform.mPosition = Vec3(100, 5, 0);
    transform.mRotation = Quat(Eigen::AngleAxisf(0.5f * cPi, Vec3::UnitY())); // local x -> world -z
    std::vector<Vec3> collected;
    mesh->CollectTriangles(AABB(Vec3(99, 4, -2), Vec3(102, 6, 2)), transform, collected);
    ASSERT_EQ(collected.size(), 3u); // Only the triangle near the local origin
    EXPECT_TRUE(collected[0].isApprox(Vec3(100, 5, 0)));
    EXPECT_TRUE(collected[1].isApprox(Vec3(101, 5, 0), 1e-5f));  // local (0, 0, 1)
    EXPECT_TRUE(collected[2].isApprox(Vec3(100, 5, -1), 1e-5f)); // local (1, 0, 0)

    collected.clear();
    mesh->CollectTriangles(AABB(Vec3(0, 0, 0), Vec3(1, 1, 1)), transform, collected);
    EXPECT_TRUE(collected.empty());
}
