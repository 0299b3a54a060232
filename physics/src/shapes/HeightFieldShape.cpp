#include "cairn/physics/shapes/HeightFieldShape.h"

#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <cassert>
#include <string>

namespace cairn::physics
{

namespace
{

// Cell (x, z) has corners p00 = sample (x, z), p10 = (x + 1, z), p01 = (x, z + 1), p11 = (x + 1, z + 1) and
// is split along the p00-p11 diagonal into half 0 = (p00, p01, p11) and half 1 = (p00, p11, p10); both face
// +Y. Edge i of a triangle runs from its vertex i to vertex i + 1, so:
//   half 0: edge01 = x side (shared with half 1 of cell x - 1), edge12 = z + 1 side (half 1 of cell z + 1),
//           edge20 = diagonal
//   half 1: edge01 = diagonal, edge12 = x + 1 side (half 0 of cell x + 1), edge20 = z side (half 0 of cell z
//   - 1)

/// Neighbour across one edge of a cell half: cell offset, which half, and which of the neighbour's vertices
/// is the apex (its vertex not on the shared edge).
struct EdgeNeighbour
{
    int mDx;
    int mDz;
    int mHalf;
    int mApex;
};

constexpr EdgeNeighbour cNeighbours[2][3] = {
    {{-1, 0, 1, 0}, {0, 1, 1, 1}, {0, 0, 1, 2}},
    {{0, 0, 0, 1}, {1, 0, 0, 2}, {0, -1, 0, 0}},
};

/// Sample offsets (dx, dz) of the 3 vertices of each half, in counter-clockwise order seen from +Y.
constexpr int cHalfCorners[2][3][2] = {{{0, 0}, {0, 1}, {1, 1}}, {{0, 0}, {1, 1}, {1, 0}}};

/// A cell exists when none of its 4 corner samples is a hole.
bool IsSolidCell(const HeightFieldShape& inField, uint32_t inX, uint32_t inZ)
{
    return !std::isnan(inField.GetHeight(inX, inZ)) && !std::isnan(inField.GetHeight(inX + 1, inZ)) &&
           !std::isnan(inField.GetHeight(inX, inZ + 1)) && !std::isnan(inField.GetHeight(inX + 1, inZ + 1));
}

/// Same as IsSolidCell, but false for cells outside the grid.
bool IsSolidCellSafe(const HeightFieldShape& inField, int64_t inX, int64_t inZ)
{
    return inX >= 0 && inZ >= 0 && inX + 1 < int64_t(inField.GetSampleCountX()) &&
           inZ + 1 < int64_t(inField.GetSampleCountZ()) && IsSolidCell(inField, uint32_t(inX), uint32_t(inZ));
}

Vec3 SamplePosition(const HeightFieldShape& inField, uint32_t inX, uint32_t inZ)
{
    return {float(inX) * inField.GetCellSize(), inField.GetHeight(inX, inZ),
            float(inZ) * inField.GetCellSize()};
}

void CellTriangle(const HeightFieldShape& inField, uint32_t inX, uint32_t inZ, int inHalf, Vec3 outV[3])
{
    for (int i = 0; i < 3; ++i)
        outV[i] = SamplePosition(inField, inX + cHalfCorners[inHalf][i][0], inZ + cHalfCorners[inHalf][i][1]);
}

/// A cell half's normal, not normalised (IsEdgeActive takes any length): never zero, its y is the cell size
/// squared; finite, the heights are bounded (Create).
Vec3 FaceNormal(const Vec3 inV[3])
{
    return (inV[1] - inV[0]).cross(inV[2] - inV[0]);
}

/// Edge flags of a cell half, from its neighbours (at creation).
uint8_t ActiveEdges(const HeightFieldShape& inField, uint32_t inX, uint32_t inZ, int inHalf,
                    const Vec3 inV[3])
{
    const Vec3 normal = FaceNormal(inV);
    uint8_t active = 0;
    for (int edge = 0; edge < 3; ++edge)
    {
        const EdgeNeighbour& n = cNeighbours[inHalf][edge];
        const int64_t nx = int64_t(inX) + n.mDx;
        const int64_t nz = int64_t(inZ) + n.mDz;
        // Borders of the field and edges next to holes have no neighbour: they stay active
        if (!IsSolidCellSafe(inField, nx, nz))
        {
            active |= uint8_t(1u << edge);
            continue;
        }
        Vec3 other[3];
        CellTriangle(inField, uint32_t(nx), uint32_t(nz), n.mHalf, other);
        if (ShapeHelpers::IsEdgeActive(normal, inV[edge], FaceNormal(other), other[n.mApex],
                                       TriangleMeshShape::cActiveEdgeCosThreshold))
            active |= uint8_t(1u << edge);
    }
    return active;
}

/// Visits both halves of a solid cell (those overlapping inBox, when given). Ray casts skip the edge flags
/// (inWithEdges false): they do not use them.
void VisitCell(const HeightFieldShape& inField, uint32_t inX, uint32_t inZ, const AABB* inBox,
               bool inWithEdges, TriangleVisitor inVisitor)
{
    if (!IsSolidCell(inField, inX, inZ)) return;
    for (int half = 0; half < 2; ++half)
    {
        Triangle triangle;
        CellTriangle(inField, inX, inZ, half, triangle.mV);
        if (inBox != nullptr &&
            !ShapeHelpers::TriangleBounds(triangle.mV[0], triangle.mV[1], triangle.mV[2]).Overlaps(*inBox))
            continue;
        if (inWithEdges)
            triangle.mActiveEdges = uint8_t(inField.GetCellActiveEdges(inX, inZ) >> (3 * half) & 7u);
        triangle.mSubShape =
            uint32_t((inX + size_t(inZ) * (inField.GetSampleCountX() - 1)) * 2 + size_t(half));
        inVisitor(triangle);
    }
}

/// Cells [outFirst, outLast] along one axis covering [inMin, inMax]; false when none does.
bool CellRange(float inMin, float inMax, uint32_t inSampleCount, float inCellSize, uint32_t& outFirst,
               uint32_t& outLast)
{
    // Clamp in float before converting: the box may reach far beyond the field
    const float last = float(inSampleCount - 2);
    const float first = std::floor(inMin / inCellSize);
    const float end = std::floor(inMax / inCellSize);
    if (!(end >= 0.0f && first <= last)) return false;
    outFirst = uint32_t(std::max(first, 0.0f));
    outLast = uint32_t(std::min(end, last));
    return true;
}

/// Fraction at which the ray leaves the box (cLargeFloat if it never does along any axis).
float ExitFraction(const AABB& inBox, const Vec3& inOrigin, const Vec3& inInvDirection)
{
    float tExit = cLargeFloat;
    for (int axis = 0; axis < 3; ++axis)
    {
        const float t1 = (inBox.mMin[axis] - inOrigin[axis]) * inInvDirection[axis];
        const float t2 = (inBox.mMax[axis] - inOrigin[axis]) * inInvDirection[axis];
        const float far = std::max(t1, t2);
        if (!std::isnan(far)) tExit = std::min(tExit, far);
    }
    return tExit;
}

/// Walks the cells under the segment between fractions inStart and inEnd in ray order (2D DDA over the xz
/// projection), calling inTestCell on each, and stops once ioBestT (updated by inTestCell) is within the
/// current cell: every later cell is further along the ray.
template <class TestCell>
void WalkCells(const HeightFieldShape& inField, const RayCast& inRay, float inStart, float inEnd,
               const float& inBestT, TestCell&& inTestCell)
{
    const float cellSize = inField.GetCellSize();
    const float du = inRay.mDirection.x() / cellSize;
    const float dw = inRay.mDirection.z() / cellSize;
    const float u = inRay.mOrigin.x() / cellSize + inStart * du;
    const float w = inRay.mOrigin.z() / cellSize + inStart * dw;
    const int64_t maxX = int64_t(inField.GetSampleCountX()) - 2;
    const int64_t maxZ = int64_t(inField.GetSampleCountZ()) - 2;
    int64_t x = std::clamp(int64_t(std::floor(u)), int64_t(0), maxX);
    int64_t z = std::clamp(int64_t(std::floor(w)), int64_t(0), maxZ);
    const int stepX = du > 0.0f ? 1 : -1;
    const int stepZ = dw > 0.0f ? 1 : -1;
    // Fraction at which the next x (z) grid line is crossed, and the fraction between two such lines
    const float deltaX = du != 0.0f ? std::abs(1.0f / du) : cLargeFloat;
    const float deltaZ = dw != 0.0f ? std::abs(1.0f / dw) : cLargeFloat;
    float nextX = du != 0.0f ? inStart + (float(x + (stepX > 0 ? 1 : 0)) - u) / du : cLargeFloat;
    float nextZ = dw != 0.0f ? inStart + (float(z + (stepZ > 0 ? 1 : 0)) - w) / dw : cLargeFloat;

    for (int64_t step = 0, maxSteps = maxX + maxZ + 4; step < maxSteps; ++step)
    {
        inTestCell(x, z);
        const float cellExit = std::min(nextX, nextZ);
        if (inBestT <= cellExit || cellExit > inEnd) return;
        if (nextX < nextZ)
        {
            x += stepX;
            nextX += deltaX;
        }
        else
        {
            z += stepZ;
            nextZ += deltaZ;
        }
        if (x < 0 || z < 0 || x > maxX || z > maxZ) return;
    }
}

} // namespace

Result<std::shared_ptr<const HeightFieldShape>> HeightFieldShape::Create(uint32_t inSampleCountX,
                                                                         uint32_t inSampleCountZ,
                                                                         float inCellSize,
                                                                         std::span<const float> inHeights)
{
    if (inSampleCountX < 2 || inSampleCountZ < 2)
        return MakeError(ErrorCode::DegenerateShape, "HeightFieldShape: needs at least 2 x 2 samples, got " +
                                                         std::to_string(inSampleCountX) + " x " +
                                                         std::to_string(inSampleCountZ));
    if (uint64_t(inSampleCountX - 1) * uint64_t(inSampleCountZ - 1) > cMaxCells)
        return MakeError(ErrorCode::InvalidArgument, "HeightFieldShape: " + std::to_string(inSampleCountX) +
                                                         " x " + std::to_string(inSampleCountZ) +
                                                         " samples are more than 2^31 cells");
    if (uint64_t(inSampleCountX) * uint64_t(inSampleCountZ) != uint64_t(inHeights.size()))
        return MakeError(ErrorCode::InvalidArgument, "HeightFieldShape: " + std::to_string(inSampleCountX) +
                                                         " x " + std::to_string(inSampleCountZ) +
                                                         " samples need as many heights, got " +
                                                         std::to_string(inHeights.size()));
    if (!std::isfinite(inCellSize))
        return MakeError(ErrorCode::InvalidArgument, "HeightFieldShape: cell size must be finite");
    // A millimetre at least: the ray walk divides by it, and coordinates over cells of 1e-25 m overflow its
    // cell indices
    if (!(inCellSize >= 1e-3f))
        return MakeError(ErrorCode::DegenerateShape, "HeightFieldShape: cell size must be at least 1 mm");
    if (double(std::max(inSampleCountX, inSampleCountZ) - 1) * inCellSize > cMaxWorldCoordinate)
        return MakeError(ErrorCode::InvalidArgument, "HeightFieldShape: extent exceeds cMaxWorldCoordinate");
    for (size_t i = 0; i < inHeights.size(); ++i)
        if (std::isinf(inHeights[i]) || std::abs(inHeights[i]) > cMaxWorldCoordinate)
            return MakeError(ErrorCode::InvalidArgument, "HeightFieldShape: height " + std::to_string(i) +
                                                             " is infinite or beyond cMaxWorldCoordinate");

    auto shape = std::make_shared<HeightFieldShape>(inSampleCountX, inSampleCountZ, inCellSize,
                                                    std::vector<float>(inHeights.begin(), inHeights.end()));
    // Empty bounds mean that every cell touches a hole: nothing would be left to collide with
    if (shape->GetLocalBounds().IsEmpty())
        return MakeError(ErrorCode::DegenerateShape, "HeightFieldShape: every cell touches a hole sample");
    return std::shared_ptr<const HeightFieldShape>(std::move(shape));
}

HeightFieldShape::HeightFieldShape(uint32_t inSampleCountX, uint32_t inSampleCountZ, float inCellSize,
                                   std::vector<float> inHeights)
    : Shape(ShapeType::HeightField), mSampleCountX(inSampleCountX), mSampleCountZ(inSampleCountZ),
      mCellSize(inCellSize), mHeights(std::move(inHeights))
{
    assert(mSampleCountX >= 2 && mSampleCountZ >= 2 &&
           mHeights.size() == size_t(mSampleCountX) * mSampleCountZ);
    // Bounds over solid cells only, so that borders made of holes do not inflate them; each solid cell's edge
    // flags (about 85 ns a cell), which a visit used to work out for each triangle it passed
    mCellActiveEdges.assign(size_t(mSampleCountX - 1) * (mSampleCountZ - 1), 0);
    for (uint32_t z = 0; z + 1 < mSampleCountZ; ++z)
        for (uint32_t x = 0; x + 1 < mSampleCountX; ++x)
        {
            if (!IsSolidCell(*this, x, z)) continue;
            for (uint32_t corner = 0; corner < 4; ++corner)
                mBounds.Encapsulate(SamplePosition(*this, x + corner % 2, z + corner / 2));
            uint8_t edges = 0;
            for (int half = 0; half < 2; ++half)
            {
                Vec3 v[3];
                CellTriangle(*this, x, z, half, v);
                edges |= uint8_t(ActiveEdges(*this, x, z, half, v) << (3 * half));
            }
            mCellActiveEdges[x + size_t(z) * (mSampleCountX - 1)] = edges;
        }
}

AABB HeightFieldShape::GetLocalBounds() const
{
    return mBounds;
}

MassProperties HeightFieldShape::GetMassProperties(float /*inDensity*/) const
{
    return {};
}

void HeightFieldShape::VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const
{
    if (!inLocalBox.Overlaps(mBounds)) return;
    uint32_t x0, x1, z0, z1;
    if (!CellRange(inLocalBox.mMin.x(), inLocalBox.mMax.x(), mSampleCountX, mCellSize, x0, x1) ||
        !CellRange(inLocalBox.mMin.z(), inLocalBox.mMax.z(), mSampleCountZ, mCellSize, z0, z1))
        return;
    for (uint32_t z = z0; z <= z1; ++z)
        for (uint32_t x = x0; x <= x1; ++x)
            VisitCell(*this, x, z, &inLocalBox, true, inVisitor);
}

bool HeightFieldShape::CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const
{
    if (!IsFinite(inLocalRay.mOrigin) || !IsFinite(inLocalRay.mDirection) || !(ioHit.mFraction >= 0.0f))
        return false;

    // Clip the segment to the (slightly grown) bounds so that the walk starts and ends over the grid
    const AABB grown = mBounds.Expanded(1.0e-4f * std::max(mCellSize, mBounds.Size().maxCoeff()));
    const Vec3 invDirection = SafeReciprocal(inLocalRay.mDirection);
    const float maxFraction = std::min(ioHit.mFraction, 1.0f);
    const float tStart = grown.RayEntryFraction(inLocalRay.mOrigin, invDirection, maxFraction);
    if (tStart > maxFraction) return false;
    const float tEnd = std::min(ExitFraction(grown, inLocalRay.mOrigin, invDirection), maxFraction);

    float bestT = cLargeFloat;
    Triangle bestTriangle;
    auto testCell = [&](int64_t inX, int64_t inZ)
    {
        if (!IsSolidCellSafe(*this, inX, inZ)) return;
        VisitCell(*this, uint32_t(inX), uint32_t(inZ), nullptr, false,
                  [&](const Triangle& inTriangle)
                  {
                      const float t = ShapeHelpers::RayTriangleFraction(inLocalRay, inTriangle.mV[0],
                                                                        inTriangle.mV[1], inTriangle.mV[2]);
                      if (t < bestT && t < ioHit.mFraction)
                      {
                          bestT = t;
                          bestTriangle = inTriangle;
                      }
                  });
    };
    WalkCells(*this, inLocalRay, tStart, tEnd, bestT, testCell);

    if (bestT == cLargeFloat) return false;
    ioHit.mFraction = bestT;
    ioHit.mNormal = ShapeHelpers::TriangleNormalFacing(bestTriangle.mV[0], bestTriangle.mV[1],
                                                       bestTriangle.mV[2], inLocalRay.mDirection);
    ioHit.mSubShape = bestTriangle.mSubShape;
    return true;
}

} // namespace cairn::physics
