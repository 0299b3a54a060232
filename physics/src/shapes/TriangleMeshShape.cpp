#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <string>
#include <unordered_map>

namespace cairn::physics
{

namespace
{

/// Leaves hold at most this many triangles: small enough for cheap leaf tests, large enough to keep the tree
/// small.
constexpr uint32_t cMaxLeafTriangles = 4;

/// Depth bound of the traversal stack; median splits halve the count, so 64 levels cover any uint32_t count.
constexpr int cMaxStackDepth = 64;

/// A mesh triangle with its vertices inline (no index indirection while traversing).
struct MeshTriangle
{
    Vec3 mV[3];
    uint8_t mActiveEdges = cAllEdgesActive;
    SubShapeID mSubShape = 0; ///< Index in the triangle list given to Create()
};

/// A BVH node: a leaf (mCount > 0) holds triangles [mFirst, mFirst + mCount); an inner node's children
/// are the next node and node mFirst.
struct BvhNode
{
    AABB mBounds;
    uint32_t mFirst = 0;
    uint32_t mCount = 0;
};

bool IsDegenerate(const Vec3& inV0, const Vec3& inV1, const Vec3& inV2)
{
    const Vec3 e1 = inV1 - inV0;
    const Vec3 e2 = inV2 - inV0;
    const float longest = std::max({e1.squaredNorm(), e2.squaredNorm(), (inV2 - inV1).squaredNorm()});
    // Relative to the longest edge, so that needles are dropped whatever the mesh scale
    return !(e1.cross(e2).norm() > 1.0e-6f * longest);
}

/// Position key for welding vertices that share a position but not an index.
using PositionKey = std::array<float, 3>;

} // namespace

struct TriangleMeshShape::Impl
{
    std::vector<MeshTriangle> mTriangles; ///< Reordered so that every BVH leaf is a contiguous range
    std::vector<BvhNode> mNodes;          ///< Node 0 is the root

    /// Median split along the longest axis of the centroids, recursively.
    uint32_t BuildNode(uint32_t inFirst, uint32_t inCount, std::vector<Vec3>& ioCentroids);

    /// Marks edges shared with a flat or concave neighbour inactive.
    void ComputeActiveEdges();

    /// Calls inLeaf(triangle) for every triangle in a leaf whose bounds pass inNodeTest(bounds).
    template <class NodeTest, class LeafVisitor>
    void Traverse(NodeTest&& inNodeTest, LeafVisitor&& inLeaf) const;
};

uint32_t TriangleMeshShape::Impl::BuildNode(uint32_t inFirst, uint32_t inCount,
                                            std::vector<Vec3>& ioCentroids)
{
    const uint32_t index = uint32_t(mNodes.size());
    mNodes.emplace_back();
    AABB bounds, centroidBounds;
    for (uint32_t i = inFirst; i < inFirst + inCount; ++i)
    {
        const MeshTriangle& t = mTriangles[i];
        bounds.Encapsulate(ShapeHelpers::TriangleBounds(t.mV[0], t.mV[1], t.mV[2]));
        centroidBounds.Encapsulate(ioCentroids[i]);
    }
    mNodes[index].mBounds = bounds;
    if (inCount <= cMaxLeafTriangles)
    {
        mNodes[index].mFirst = inFirst;
        mNodes[index].mCount = inCount;
        return index;
    }

    int axis = 0;
    centroidBounds.Size().maxCoeff(&axis);
    // Sort an index permutation, then apply it to both arrays so triangles and centroids stay paired
    const uint32_t half = inCount / 2;
    std::vector<uint32_t> order(inCount);
    std::iota(order.begin(), order.end(), inFirst);
    std::nth_element(order.begin(), order.begin() + half, order.end(),
                     [&](uint32_t a, uint32_t b) { return ioCentroids[a][axis] < ioCentroids[b][axis]; });
    std::vector<MeshTriangle> triangles(inCount);
    std::vector<Vec3> centroids(inCount);
    for (uint32_t i = 0; i < inCount; ++i)
    {
        triangles[i] = mTriangles[order[i]];
        centroids[i] = ioCentroids[order[i]];
    }
    std::copy(triangles.begin(), triangles.end(), mTriangles.begin() + inFirst);
    std::copy(centroids.begin(), centroids.end(), ioCentroids.begin() + inFirst);

    BuildNode(inFirst, half, ioCentroids);
    const uint32_t right = BuildNode(inFirst + half, inCount - half, ioCentroids);
    mNodes[index].mFirst = right;
    return index;
}

void TriangleMeshShape::Impl::ComputeActiveEdges()
{
    // Weld by position: meshes often repeat vertices per face, which would hide shared edges
    std::map<PositionKey, uint32_t> weld;
    auto vertexId = [&](const Vec3& inV) {
        return weld.emplace(PositionKey{inV.x(), inV.y(), inV.z()}, uint32_t(weld.size())).first->second;
    };
    struct EdgeUse
    {
        uint32_t mTriangle;
        int mEdge;
    };
    std::unordered_map<uint64_t, std::vector<EdgeUse>> edges;
    for (uint32_t t = 0; t < mTriangles.size(); ++t)
    {
        uint32_t ids[3];
        for (int i = 0; i < 3; ++i)
            ids[i] = vertexId(mTriangles[t].mV[i]);
        for (int e = 0; e < 3; ++e)
        {
            const uint32_t a = std::min(ids[e], ids[(e + 1) % 3]);
            const uint32_t b = std::max(ids[e], ids[(e + 1) % 3]);
            edges[(uint64_t(a) << 32) | b].push_back({t, e});
        }
    }

    auto normal = [&](uint32_t inT)
    {
        const MeshTriangle& t = mTriangles[inT];
        return ShapeHelpers::SafeNormalized((t.mV[1] - t.mV[0]).cross(t.mV[2] - t.mV[0]), Vec3::UnitY());
    };
    for (const auto& [key, uses] : edges)
    {
        if (uses.size() != 2) continue; // Borders and non-manifold edges stay active
        const EdgeUse& a = uses[0];
        const EdgeUse& b = uses[1];
        const MeshTriangle& ta = mTriangles[a.mTriangle];
        const MeshTriangle& tb = mTriangles[b.mTriangle];
        // Consistently wound neighbours run the shared edge in opposite directions; otherwise "concave"
        // has no meaning and the edge stays active
        if (ta.mV[a.mEdge] != tb.mV[(b.mEdge + 1) % 3]) continue;
        const Vec3 apexB = tb.mV[(b.mEdge + 2) % 3];
        if (!ShapeHelpers::IsEdgeActive(normal(a.mTriangle), ta.mV[a.mEdge], normal(b.mTriangle), apexB,
                                        cActiveEdgeCosThreshold))
        {
            mTriangles[a.mTriangle].mActiveEdges &= uint8_t(~(1u << a.mEdge));
            mTriangles[b.mTriangle].mActiveEdges &= uint8_t(~(1u << b.mEdge));
        }
    }
}

template <class NodeTest, class LeafVisitor>
void TriangleMeshShape::Impl::Traverse(NodeTest&& inNodeTest, LeafVisitor&& inLeaf) const
{
    uint32_t stack[cMaxStackDepth];
    int size = 0;
    stack[size++] = 0;
    while (size > 0)
    {
        const BvhNode& node = mNodes[stack[--size]];
        if (!inNodeTest(node.mBounds)) continue;
        if (node.mCount > 0)
        {
            for (uint32_t i = node.mFirst; i < node.mFirst + node.mCount; ++i)
                inLeaf(mTriangles[i]);
            continue;
        }
        const uint32_t left = uint32_t(&node - mNodes.data()) + 1;
        stack[size++] = node.mFirst;
        stack[size++] = left;
    }
}

Result<std::shared_ptr<const TriangleMeshShape>>
TriangleMeshShape::Create(std::span<const Vec3> inVertices,
                          std::span<const std::array<uint32_t, 3>> inTriangles)
{
    for (size_t i = 0; i < inVertices.size(); ++i)
        if (!IsValidWorldPosition(inVertices[i]))
            return MakeError(ErrorCode::InvalidArgument,
                             "TriangleMeshShape: vertex " + std::to_string(i) +
                                 " is NaN, infinite or beyond cMaxWorldCoordinate");
    if (inTriangles.empty()) return MakeError(ErrorCode::DegenerateShape, "TriangleMeshShape: no triangles");
    if (inTriangles.size() > size_t(std::numeric_limits<uint32_t>::max() / 2))
        return MakeError(ErrorCode::InvalidArgument, "TriangleMeshShape: too many triangles");

    auto impl = std::make_unique<Impl>();
    impl->mTriangles.reserve(inTriangles.size());
    for (size_t t = 0; t < inTriangles.size(); ++t)
    {
        MeshTriangle triangle;
        for (int i = 0; i < 3; ++i)
        {
            const uint32_t index = inTriangles[t][i];
            if (index >= inVertices.size())
                return MakeError(ErrorCode::InvalidArgument,
                                 "TriangleMeshShape: triangle " + std::to_string(t) + " uses vertex index " +
                                     std::to_string(index) + " but there are only " +
                                     std::to_string(inVertices.size()) + " vertices");
            triangle.mV[i] = inVertices[index];
        }
        triangle.mSubShape = SubShapeID(t);
        if (!IsDegenerate(triangle.mV[0], triangle.mV[1], triangle.mV[2]))
            impl->mTriangles.push_back(triangle);
    }
    if (impl->mTriangles.empty())
        return MakeError(ErrorCode::DegenerateShape,
                         "TriangleMeshShape: every triangle is degenerate (zero area)");

    impl->ComputeActiveEdges();
    std::vector<Vec3> centroids;
    centroids.reserve(impl->mTriangles.size());
    for (const MeshTriangle& t : impl->mTriangles)
        centroids.push_back((t.mV[0] + t.mV[1] + t.mV[2]) / 3.0f);
    impl->mNodes.reserve(2 * impl->mTriangles.size());
    impl->BuildNode(0, uint32_t(impl->mTriangles.size()), centroids);
    return std::shared_ptr<const TriangleMeshShape>(std::make_shared<TriangleMeshShape>(std::move(impl)));
}

TriangleMeshShape::TriangleMeshShape(std::unique_ptr<Impl> inImpl)
    : Shape(ShapeType::TriangleMesh), mImpl(std::move(inImpl))
{
}

TriangleMeshShape::~TriangleMeshShape() = default;

size_t TriangleMeshShape::GetTriangleCount() const
{
    return mImpl->mTriangles.size();
}

AABB TriangleMeshShape::GetLocalBounds() const
{
    return mImpl->mNodes.front().mBounds;
}

MassProperties TriangleMeshShape::GetMassProperties(float /*inDensity*/) const
{
    return {};
}

bool TriangleMeshShape::CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const
{
    const Vec3 invDirection = SafeReciprocal(inLocalRay.mDirection);
    float closest = std::min(ioHit.mFraction, 1.0f);
    const MeshTriangle* hitTriangle = nullptr;
    float hitFraction = cLargeFloat;
    mImpl->Traverse(
        [&](const AABB& inBounds)
        {
            // Closed-interval test so that hits exactly at the current best are still reached (then rejected)
            return inBounds.RayEntryFraction(inLocalRay.mOrigin, invDirection, closest) <= closest;
        },
        [&](const MeshTriangle& inTriangle)
        {
            const float t = ShapeHelpers::RayTriangleFraction(inLocalRay, inTriangle.mV[0], inTriangle.mV[1],
                                                              inTriangle.mV[2]);
            if (t < ioHit.mFraction && t < hitFraction)
            {
                hitFraction = t;
                hitTriangle = &inTriangle;
                closest = t;
            }
        });
    if (hitTriangle == nullptr) return false;
    ioHit.mFraction = hitFraction;
    ioHit.mNormal = ShapeHelpers::TriangleNormalFacing(hitTriangle->mV[0], hitTriangle->mV[1],
                                                       hitTriangle->mV[2], inLocalRay.mDirection);
    ioHit.mSubShape = hitTriangle->mSubShape;
    return true;
}

void TriangleMeshShape::VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const
{
    mImpl->Traverse(
        [&](const AABB& inBounds) { return inBounds.Overlaps(inLocalBox); },
        [&](const MeshTriangle& inTriangle)
        {
            if (!ShapeHelpers::TriangleBounds(inTriangle.mV[0], inTriangle.mV[1], inTriangle.mV[2])
                     .Overlaps(inLocalBox))
                return;
            Triangle triangle{{inTriangle.mV[0], inTriangle.mV[1], inTriangle.mV[2]},
                              inTriangle.mActiveEdges,
                              inTriangle.mSubShape};
            inVisitor(triangle);
        });
}

} // namespace cairn::physics
