#include "cairn/physics/shapes/ConvexHullShape.h"

#include <algorithm>
#include <string>
#include <unordered_map>
#include <unordered_set>

namespace cairn::physics
{

namespace
{

// Construction runs in double: the input floats are exact in double, so plane tests only suffer from the
// (tiny) rounding of the construction itself, far below the geometric tolerance
using DVec3 = Eigen::Vector3d;

/// Points closer than this fraction of the cloud's bounding-box diagonal to a plane count as on it.
constexpr double cRelativeTolerance = 1.0e-5;

/// Plane distances below this fraction of the diagonal are rounding noise of the double computation.
constexpr double cRelativeNoise = 1.0e-11;

/// Merging also requires nearly parallel normals so that tiny slivers near an edge are not folded into a
/// face.
constexpr double cMergeCos = 0.999;

uint64_t EdgeKey(uint32_t inFrom, uint32_t inTo)
{
    return (uint64_t(inFrom) << 32) | inTo;
}

/// A triangle of the hull under construction, with the points still outside it.
struct BuildFace
{
    uint32_t mV[3];
    DVec3 mNormal;
    double mConstant;
    std::vector<uint32_t> mOutside;
    bool mAlive = true;

    double Distance(const DVec3& inPoint) const { return mNormal.dot(inPoint) - mConstant; }
};

/// Quickhull over a point cloud: builds the triangles, then merges coplanar ones into polygons.
class HullBuilder
{
public:
    explicit HullBuilder(std::span<const Vec3> inPoints)
    {
        mPoints.reserve(inPoints.size());
        for (const Vec3& p : inPoints)
            mPoints.push_back(p.cast<double>());
    }

    /// Runs the whole construction; on success fills outVertices/outFaces.
    Status Build(std::vector<Vec3>& outVertices, std::vector<ConvexHullShape::Face>& outFaces)
    {
        if (Status status = BuildInitialSimplex(); !status) return status;
        AssignInitialOutsideSets();
        while (AddNextPoint())
        {
        }
        if (!IsClosedManifold())
            return MakeError(
                ErrorCode::DegenerateShape,
                "ConvexHullShape: hull construction failed (numerically degenerate point cloud)");
        MergeFaces(outVertices, outFaces);
        return Status::Ok();
    }

private:
    /// Picks 4 well separated points, rejecting clouds without volume.
    Status BuildInitialSimplex()
    {
        Eigen::AlignedBox3d box;
        for (const DVec3& p : mPoints)
            box.extend(p);
        mTolerance = cRelativeTolerance * box.diagonal().norm();
        mNoise = cRelativeNoise * box.diagonal().norm();

        // The two most distant of the six axis-extreme points span the cloud well
        uint32_t extremes[6] = {};
        for (uint32_t i = 0; i < mPoints.size(); ++i)
            for (int axis = 0; axis < 3; ++axis)
            {
                if (mPoints[i][axis] < mPoints[extremes[2 * axis]][axis]) extremes[2 * axis] = i;
                if (mPoints[i][axis] > mPoints[extremes[2 * axis + 1]][axis]) extremes[2 * axis + 1] = i;
            }
        double best = -1.0;
        uint32_t i0 = 0, i1 = 0;
        for (uint32_t a : extremes)
            for (uint32_t b : extremes)
                if (const double d = (mPoints[a] - mPoints[b]).squaredNorm(); d > best)
                {
                    best = d;
                    i0 = a;
                    i1 = b;
                }
        if (!(std::sqrt(best) > mTolerance))
            return MakeError(ErrorCode::DegenerateShape, "ConvexHullShape: all points coincide");

        const DVec3 axis = (mPoints[i1] - mPoints[i0]).normalized();
        const uint32_t i2 = FurthestPoint(
            [&](const DVec3& inP)
            {
                const DVec3 r = inP - mPoints[i0];
                return (r - r.dot(axis) * axis).norm();
            });
        const DVec3 r2 = mPoints[i2] - mPoints[i0];
        if (!((r2 - r2.dot(axis) * axis).norm() > mTolerance))
            return MakeError(ErrorCode::DegenerateShape, "ConvexHullShape: all points are collinear");

        const DVec3 normal = axis.cross(r2).normalized();
        const uint32_t i3 =
            FurthestPoint([&](const DVec3& inP) { return std::abs(normal.dot(inP - mPoints[i0])); });
        if (!(std::abs(normal.dot(mPoints[i3] - mPoints[i0])) > mTolerance))
            return MakeError(ErrorCode::DegenerateShape,
                             "ConvexHullShape: all points are coplanar (no volume)");

        AddFace(i0, i1, i2, i3);
        AddFace(i0, i1, i3, i2);
        AddFace(i0, i2, i3, i1);
        AddFace(i1, i2, i3, i0);
        mUsed = {i0, i1, i2, i3};
        return Status::Ok();
    }

    template <class F> uint32_t FurthestPoint(F&& inDistance) const
    {
        uint32_t best = 0;
        double bestDistance = -1.0;
        for (uint32_t i = 0; i < mPoints.size(); ++i)
            if (const double d = inDistance(mPoints[i]); d > bestDistance)
            {
                bestDistance = d;
                best = i;
            }
        return best;
    }

    /// Adds triangle (a, b, c) wound so that inInside lies behind it.
    void AddFace(uint32_t inA, uint32_t inB, uint32_t inC, uint32_t inInside)
    {
        const DVec3 n = (mPoints[inB] - mPoints[inA]).cross(mPoints[inC] - mPoints[inA]);
        if (n.dot(mPoints[inInside] - mPoints[inA]) > 0.0) std::swap(inB, inC);
        AddOrientedFace(inA, inB, inC);
    }

    void AddOrientedFace(uint32_t inA, uint32_t inB, uint32_t inC)
    {
        BuildFace face;
        face.mV[0] = inA;
        face.mV[1] = inB;
        face.mV[2] = inC;
        const DVec3 n = (mPoints[inB] - mPoints[inA]).cross(mPoints[inC] - mPoints[inA]);
        const double length = n.norm();
        face.mNormal = length > 0.0 ? DVec3(n / length) : DVec3::UnitY();
        face.mConstant = face.mNormal.dot(mPoints[inA]);
        for (int e = 0; e < 3; ++e)
            mLiveEdges[EdgeKey(face.mV[e], face.mV[(e + 1) % 3])] = mFaces.size();
        mFaces.push_back(std::move(face));
    }

    /// The live face on the other side of directed edge (inFrom, inTo), or SIZE_MAX.
    size_t Neighbour(uint32_t inFrom, uint32_t inTo) const
    {
        const auto it = mLiveEdges.find(EdgeKey(inTo, inFrom));
        return it != mLiveEdges.end() ? it->second : SIZE_MAX;
    }

    /// The faces the eye point sees, grown from inStart across neighbours so that the region stays connected
    /// (a scan of all faces could pick up a stray, disconnected face and break the horizon into pieces).
    /// "Sees" means in front by more than the rounding noise only, not by the coplanarity tolerance:
    /// absorbing a face the eye is slightly behind can fold the new faces over it, and keeping a face the eye
    /// is slightly in front of only leaves a nearly flat joint that the final merge removes.
    std::vector<size_t> VisibleFaces(size_t inStart, const DVec3& inEye,
                                     std::unordered_set<size_t>& outVisible) const
    {
        std::vector<size_t> visible = {inStart};
        outVisible = {inStart};
        for (size_t i = 0; i < visible.size(); ++i)
        {
            const BuildFace& face = mFaces[visible[i]];
            for (int e = 0; e < 3; ++e)
            {
                const size_t neighbour = Neighbour(face.mV[e], face.mV[(e + 1) % 3]);
                if (neighbour != SIZE_MAX && !outVisible.contains(neighbour) &&
                    mFaces[neighbour].Distance(inEye) > mNoise)
                {
                    outVisible.insert(neighbour);
                    visible.push_back(neighbour);
                }
            }
        }
        return visible;
    }

    /// The edges between visible and hidden faces. A new face on a horizon edge that the eye is collinear
    /// with (within rounding noise) would have no usable normal: the hidden face behind that edge then has
    /// the eye in its plane, so it joins the visible set and the horizon moves past it.
    std::vector<std::pair<uint32_t, uint32_t>> FindHorizon(const DVec3& inEye, std::vector<size_t>& ioVisible,
                                                           std::unordered_set<size_t>& ioIsVisible) const
    {
        std::vector<std::pair<uint32_t, uint32_t>> horizon;
        for (bool grown = true; grown;)
        {
            grown = false;
            horizon.clear();
            for (size_t i = 0; i < ioVisible.size(); ++i)
                for (int e = 0; e < 3; ++e)
                {
                    const uint32_t a = mFaces[ioVisible[i]].mV[e];
                    const uint32_t b = mFaces[ioVisible[i]].mV[(e + 1) % 3];
                    const size_t neighbour = Neighbour(a, b);
                    if (ioIsVisible.contains(neighbour)) continue;
                    const DVec3 edge = mPoints[b] - mPoints[a];
                    const bool degenerate = edge.cross(inEye - mPoints[a]).norm() <= mNoise * edge.norm();
                    if (degenerate && neighbour != SIZE_MAX)
                    {
                        ioIsVisible.insert(neighbour);
                        ioVisible.push_back(neighbour);
                        grown = true;
                    }
                    horizon.emplace_back(a, b);
                }
        }
        return horizon;
    }

    void AssignInitialOutsideSets()
    {
        for (uint32_t i = 0; i < mPoints.size(); ++i)
            if (std::find(mUsed.begin(), mUsed.end(), i) == mUsed.end()) AssignToFace(i, 0);
    }

    /// Puts the point in the outside set of the first live face (from inFirstFace on, then the rest) it is
    /// clearly in front of; points in front of none are inside the hull and dropped.
    void AssignToFace(uint32_t inPoint, size_t inFirstFace)
    {
        // New faces are the likely owners, but an orphan may also lie in front of an older face
        for (size_t pass = 0; pass < 2; ++pass)
        {
            const size_t begin = pass == 0 ? inFirstFace : 0;
            const size_t end = pass == 0 ? mFaces.size() : inFirstFace;
            for (size_t f = begin; f < end; ++f)
                if (mFaces[f].mAlive && mFaces[f].Distance(mPoints[inPoint]) > mTolerance)
                {
                    mFaces[f].mOutside.push_back(inPoint);
                    return;
                }
        }
    }

    /// Adds the furthest outside point of some face to the hull; false when no point is left outside.
    bool AddNextPoint()
    {
        const auto faceIt = std::find_if(mFaces.begin(), mFaces.end(),
                                         [](const BuildFace& f) { return f.mAlive && !f.mOutside.empty(); });
        if (faceIt == mFaces.end()) return false;

        const BuildFace& face = *faceIt;
        const uint32_t eye = *std::max_element(
            face.mOutside.begin(), face.mOutside.end(),
            [&](uint32_t a, uint32_t b) { return face.Distance(mPoints[a]) < face.Distance(mPoints[b]); });

        std::unordered_set<size_t> isVisible;
        std::vector<size_t> visible = VisibleFaces(size_t(faceIt - mFaces.begin()), mPoints[eye], isVisible);
        const std::vector<std::pair<uint32_t, uint32_t>> horizon =
            FindHorizon(mPoints[eye], visible, isVisible);

        std::vector<uint32_t> orphans;
        for (size_t f : visible)
        {
            BuildFace& removed = mFaces[f];
            for (int e = 0; e < 3; ++e)
                mLiveEdges.erase(EdgeKey(removed.mV[e], removed.mV[(e + 1) % 3]));
            removed.mAlive = false;
            for (uint32_t p : removed.mOutside)
                if (p != eye) orphans.push_back(p);
            removed.mOutside = {};
        }
        const size_t firstNewFace = mFaces.size();
        for (const auto& [a, b] : horizon)
            AddOrientedFace(a, b, eye);
        for (uint32_t p : orphans)
            AssignToFace(p, firstNewFace);
        return true;
    }

    /// Every directed edge of the live faces appears once and has its reverse: a closed, consistently wound
    /// surface. Fills mEdgeToFace for the merge step.
    bool IsClosedManifold()
    {
        for (size_t f = 0; f < mFaces.size(); ++f)
            if (mFaces[f].mAlive)
                for (int e = 0; e < 3; ++e)
                    if (!mEdgeToFace.emplace(EdgeKey(mFaces[f].mV[e], mFaces[f].mV[(e + 1) % 3]), f).second)
                        return false;
        for (const auto& [key, face] : mEdgeToFace)
            if (!mEdgeToFace.contains(EdgeKey(uint32_t(key), uint32_t(key >> 32)))) return false;
        return true;
    }

    /// Collects the coplanar neighbours of inSeed (flood fill) into outGroup.
    void CollectCoplanarGroup(size_t inSeed, std::vector<int>& ioGroupOf, int inGroup,
                              std::vector<size_t>& outGroup)
    {
        const BuildFace& seed = mFaces[inSeed];
        outGroup = {inSeed};
        ioGroupOf[inSeed] = inGroup;
        for (size_t i = 0; i < outGroup.size(); ++i)
        {
            const BuildFace& face = mFaces[outGroup[i]];
            for (int e = 0; e < 3; ++e)
            {
                const size_t neighbour = mEdgeToFace.at(EdgeKey(face.mV[(e + 1) % 3], face.mV[e]));
                if (ioGroupOf[neighbour] >= 0) continue;
                const BuildFace& other = mFaces[neighbour];
                const bool coplanar =
                    other.mNormal.dot(seed.mNormal) > cMergeCos &&
                    std::all_of(std::begin(other.mV), std::end(other.mV),
                                [&](uint32_t v)
                                { return std::abs(seed.Distance(mPoints[v])) <= mTolerance; });
                if (coplanar)
                {
                    ioGroupOf[neighbour] = inGroup;
                    outGroup.push_back(neighbour);
                }
            }
        }
    }

    /// Walks the boundary of a group of triangles into one counter-clockwise loop; empty if it is not a
    /// single simple loop (then the triangles are kept as separate faces).
    std::vector<uint32_t> BoundaryLoop(const std::vector<size_t>& inGroup,
                                       const std::vector<int>& inGroupOf) const
    {
        std::unordered_map<uint32_t, uint32_t> next;
        for (size_t f : inGroup)
            for (int e = 0; e < 3; ++e)
            {
                const uint32_t a = mFaces[f].mV[e];
                const uint32_t b = mFaces[f].mV[(e + 1) % 3];
                if (inGroupOf[mEdgeToFace.at(EdgeKey(b, a))] != inGroupOf[f] && !next.emplace(a, b).second)
                    return {};
            }
        std::vector<uint32_t> loop;
        uint32_t v = next.begin()->first;
        do
        {
            loop.push_back(v);
            const auto it = next.find(v);
            if (it == next.end() || loop.size() > next.size()) return {};
            v = it->second;
        } while (v != loop.front());
        return loop.size() == next.size() ? loop : std::vector<uint32_t>{};
    }

    /// Turns the live triangles into merged planar faces over a compacted vertex list.
    void MergeFaces(std::vector<Vec3>& outVertices, std::vector<ConvexHullShape::Face>& outFaces)
    {
        std::vector<int> groupOf(mFaces.size(), -1);
        std::vector<std::vector<uint32_t>> polygons;
        std::vector<size_t> group;
        for (size_t f = 0; f < mFaces.size(); ++f)
        {
            if (!mFaces[f].mAlive || groupOf[f] >= 0) continue;
            CollectCoplanarGroup(f, groupOf, int(polygons.size()), group);
            std::vector<uint32_t> loop =
                group.size() > 1 ? BoundaryLoop(group, groupOf) : std::vector<uint32_t>{};
            if (!loop.empty())
            {
                polygons.push_back(std::move(loop));
                continue;
            }
            // Not a simple loop (should not happen on a convex hull): keep the triangles as they are
            for (size_t member : group)
                polygons.push_back({mFaces[member].mV[0], mFaces[member].mV[1], mFaces[member].mV[2]});
        }

        std::unordered_map<uint32_t, uint32_t> remap;
        for (const std::vector<uint32_t>& polygon : polygons)
        {
            ConvexHullShape::Face face;
            for (uint32_t v : polygon)
            {
                const auto [it, added] = remap.emplace(v, uint32_t(outVertices.size()));
                if (added) outVertices.push_back(mPoints[v].cast<float>());
                face.mIndices.push_back(it->second);
            }
            SetFacePlane(polygon, face);
            outFaces.push_back(std::move(face));
        }
    }

    /// Newell's normal (robust for polygons with nearly collinear vertices) and the mean plane constant.
    void SetFacePlane(const std::vector<uint32_t>& inPolygon, ConvexHullShape::Face& ioFace) const
    {
        DVec3 normal = DVec3::Zero();
        DVec3 centroid = DVec3::Zero();
        for (size_t i = 0; i < inPolygon.size(); ++i)
        {
            const DVec3& a = mPoints[inPolygon[i]];
            const DVec3& b = mPoints[inPolygon[(i + 1) % inPolygon.size()]];
            normal += (a - b).cross(a + b) * 0.5;
            centroid += a;
        }
        normal.normalize();
        centroid /= double(inPolygon.size());
        ioFace.mNormal = normal.cast<float>();
        ioFace.mPlaneConstant = float(normal.dot(centroid));
    }

    std::vector<DVec3> mPoints;
    std::vector<BuildFace> mFaces;
    std::vector<uint32_t> mUsed;
    std::unordered_map<uint64_t, size_t> mLiveEdges; ///< Directed edge -> live face, during construction
    std::unordered_map<uint64_t, size_t> mEdgeToFace;
    double mTolerance = 0.0; ///< Points within this distance of a plane are on it
    double mNoise = 0.0;     ///< Rounding noise of a plane distance; anything above is a real offset
};

} // namespace

Result<std::shared_ptr<const ConvexHullShape>> ConvexHullShape::Create(std::span<const Vec3> inPoints)
{
    if (inPoints.size() > cMaxInputPoints)
        return MakeError(ErrorCode::InvalidArgument,
                         "ConvexHullShape: " + std::to_string(inPoints.size()) + " points, over the " +
                             std::to_string(cMaxInputPoints) + " a hull is built from");
    for (size_t i = 0; i < inPoints.size(); ++i)
        if (!IsValidWorldPosition(inPoints[i]))
            return MakeError(ErrorCode::InvalidArgument,
                             "ConvexHullShape: point " + std::to_string(i) +
                                 " is NaN, infinite or beyond cMaxWorldCoordinate");
    if (inPoints.size() < 4)
        return MakeError(ErrorCode::DegenerateShape,
                         "ConvexHullShape: needs at least 4 points, got " + std::to_string(inPoints.size()));

    std::vector<Vec3> vertices;
    std::vector<Face> faces;
    if (Status status = HullBuilder(inPoints).Build(vertices, faces); !status) return status.GetError();
    return std::shared_ptr<const ConvexHullShape>(
        std::make_shared<ConvexHullShape>(std::move(vertices), std::move(faces)));
}

ConvexHullShape::ConvexHullShape(std::vector<Vec3> inVertices, std::vector<Face> inFaces)
    : ConvexShape(ShapeType::ConvexHull), mVertices(std::move(inVertices)), mFaces(std::move(inFaces))
{
    for (const Vec3& v : mVertices)
        mBounds.Encapsulate(v);
}

AABB ConvexHullShape::GetLocalBounds() const
{
    return mBounds;
}

MassProperties ConvexHullShape::GetMassProperties(float inDensity) const
{
    // Sum of tetrahedra (reference point, fan triangle); the reference near the middle keeps the sums small
    DVec3 reference = DVec3::Zero();
    for (const Vec3& v : mVertices)
        reference += v.cast<double>();
    reference /= double(mVertices.size());

    double volume = 0.0;
    DVec3 firstMoment = DVec3::Zero();
    Eigen::Matrix3d secondMoment = Eigen::Matrix3d::Zero(); // Integral of r r^T over the volume
    for (const Face& face : mFaces)
    {
        const DVec3 a = mVertices[face.mIndices[0]].cast<double>() - reference;
        for (size_t i = 1; i + 1 < face.mIndices.size(); ++i)
        {
            const DVec3 b = mVertices[face.mIndices[i]].cast<double>() - reference;
            const DVec3 c = mVertices[face.mIndices[i + 1]].cast<double>() - reference;
            const double det = a.dot(b.cross(c)); // 6 x signed volume
            const DVec3 sum = a + b + c;
            volume += det / 6.0;
            firstMoment += det / 24.0 * sum;
            secondMoment +=
                det / 120.0 *
                (a * a.transpose() + b * b.transpose() + c * c.transpose() + sum * sum.transpose());
        }
    }

    MassProperties props;
    if (!(volume > 0.0)) return props;
    const DVec3 com = firstMoment / volume;
    const Eigen::Matrix3d centered = secondMoment - volume * com * com.transpose();
    const Eigen::Matrix3d inertia = centered.trace() * Eigen::Matrix3d::Identity() - centered;
    props.mMass = float(inDensity * volume);
    props.mCenterOfMass = (reference + com).cast<float>();
    props.mInertia = (double(inDensity) * inertia).cast<float>();
    return props;
}

bool ConvexHullShape::CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const
{
    // Clip the segment against every face plane; the last plane entered is the hit face
    float tEnter = 0.0f;
    float tExit = 1.0f;
    const Face* enterFace = nullptr;
    for (const Face& face : mFaces)
    {
        const float distance = face.mNormal.dot(inLocalRay.mOrigin) - face.mPlaneConstant;
        const float approach = face.mNormal.dot(inLocalRay.mDirection);
        if (approach == 0.0f)
        {
            if (distance > 0.0f) return false;
            continue;
        }
        const float t = -distance / approach;
        if (approach < 0.0f)
        {
            if (t > tEnter)
            {
                tEnter = t;
                enterFace = &face;
            }
        }
        else if (t < tExit)
            tExit = t;
        if (tEnter > tExit) return false;
    }
    if (enterFace == nullptr)
    {
        // No plane had to be entered: the origin is on or behind every face, i.e. inside
        const bool inside =
            std::all_of(mFaces.begin(), mFaces.end(),
                        [&](const Face& inFace)
                        { return inFace.mNormal.dot(inLocalRay.mOrigin) <= inFace.mPlaneConstant; });
        return inside && ShapeHelpers::ReportStartInside(inLocalRay, ioHit);
    }
    if (!(tEnter < ioHit.mFraction)) return false;
    ioHit.mFraction = tEnter;
    ioHit.mNormal = enterFace->mNormal;
    ioHit.mSubShape = 0;
    return true;
}

void ConvexHullShape::VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const
{
    if (!inLocalBox.Overlaps(mBounds)) return;
    for (const Face& face : mFaces)
        for (size_t i = 1; i + 1 < face.mIndices.size(); ++i)
        {
            const Triangle triangle{
                {mVertices[face.mIndices[0]], mVertices[face.mIndices[i]], mVertices[face.mIndices[i + 1]]}};
            if (ShapeHelpers::TriangleBounds(triangle.mV[0], triangle.mV[1], triangle.mV[2])
                    .Overlaps(inLocalBox))
                inVisitor(triangle);
        }
}

Vec3 ConvexHullShape::GetSupport(const Vec3& inDirection) const
{
    size_t best = 0;
    float bestDot = -std::numeric_limits<float>::infinity();
    for (size_t i = 0; i < mVertices.size(); ++i)
        if (const float d = mVertices[i].dot(inDirection); d > bestDot)
        {
            bestDot = d;
            best = i;
        }
    return mVertices[best];
}

void ConvexHullShape::GetSupportingFace(const Vec3& inDirection, SupportingFace& outFace) const
{
    const auto best = std::max_element(mFaces.begin(), mFaces.end(),
                                       [&](const Face& inA, const Face& inB) {
                                           return inA.mNormal.dot(inDirection) < inB.mNormal.dot(inDirection);
                                       });
    // A face with more vertices than fit is subsampled evenly: the chosen vertices still form a convex
    // polygon on the face that spans it, so the contact manifold keeps its extent
    const size_t count = best->mIndices.size();
    const size_t kept = std::min<size_t>(count, SupportingFace::cMaxVertices);
    outFace.mCount = int(kept);
    for (size_t i = 0; i < kept; ++i)
        outFace.mVertices[i] = mVertices[best->mIndices[i * count / kept]];
}

} // namespace cairn::physics
