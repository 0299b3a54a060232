#include "GeneratedLevel.h"

#include "cairn/physics/shapes/TriangleMeshShape.h"
#include "common/Mix64.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>

// Every float expression here must round the same wherever it is compiled: FindObjects reports bounds of the
// vertices MakeObject makes (in another function, after other inlining), and a seed should give the same
// level on every machine. A fused multiply-add rounds once where a multiply and an add round twice, and GCC
// fuses whenever the target has FMA (found: -march=native moved vertices out of their reported bounds).
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

namespace cairn::bake
{
using namespace cairn::physics;

namespace
{

constexpr uint32_t cGroundQuads = 8;               ///< Per side of a cell
constexpr uint32_t cGroundSide = cGroundQuads + 1; ///< Vertices per side of a cell's ground
constexpr uint32_t cRampEvery = 6;                 ///< Props 6, 12, 18... are ramps: the navmesh gets slopes
/// Props reach this far below the ground at their lowest corner, so that no edge floats above a dip
constexpr float cEmbedDepth = 0.3f;
/// Between a prop and its cell's sides, as a fraction of the cell size: a prop's bounds stay inside its cell,
/// which is what lets FindObjects look at the cells a box touches only
constexpr float cCellMargin = 0.05f;

using tools::Mix64;

/// A splitmix64 sequence as floats of 24 random bits (exact in a float, so the same everywhere).
class Dice
{
public:
    explicit Dice(uint64_t inState) : mState(inState) {}

    float Unit() ///< [0, 1)
    {
        mState += 0x9e3779b97f4a7c15ull;
        return float(uint32_t(Mix64(mState) >> 40)) * 0x1p-24f;
    }
    float Between(float inLow, float inHigh) { return inLow + (inHigh - inLow) * Unit(); }

private:
    uint64_t mState;
};

/// Like sin(2 pi t), from two parabolas: the slope is continuous, which is all terrain needs, and unlike
/// std::sin every platform gives the same bits.
float Wave(float inT)
{
    const float f = inT - std::floor(inT);
    return f < 0.5f ? 16.0f * f * (0.5f - f) : 16.0f * (f - 0.5f) * (f - 1.0f);
}

enum class ObjectKind
{
    Ground,
    Box,
    Ramp,
};

struct ObjectId
{
    uint32_t mCellX = 0, mCellZ = 0;
    uint32_t mIndex = 0; ///< 0: the ground; props from 1
};

/// An object's vertices in a fixed buffer: FindObjects makes every object of a cell just for its bounds.
struct ObjectVertices
{
    ObjectKind mKind = ObjectKind::Ground;
    uint32_t mCount = 0;
    std::array<Vec3, cGroundSide * cGroundSide> mPositions; ///< The ground has the most
};

using Triangle = std::array<uint32_t, 3>;

// Triangles as vertex indices, three by three, counter-clockwise seen from outside. Box vertex k: on the +x
// half if bit 0, the +z half if bit 1, the top if bit 2
constexpr std::array<uint32_t, 36> cBoxTriangles = {
    0, 1, 3, 0, 3, 2, // Bottom
    4, 6, 7, 4, 7, 5, // Top
    0, 2, 6, 0, 6, 4, // -x
    1, 5, 7, 1, 7, 3, // +x
    0, 4, 5, 0, 5, 1, // -z
    2, 3, 7, 2, 7, 6, // +z
};
// Ramp vertices 0-3 as the box's bottom, 4 and 5 above 1 and 3: it rises towards +x
constexpr std::array<uint32_t, 24> cRampTriangles = {
    0, 1, 3, 0, 3, 2, // Bottom
    0, 2, 5, 0, 5, 4, // Slope
    1, 4, 5, 1, 5, 3, // +x, the high end
    0, 4, 1,          // -z
    2, 3, 5,          // +z
};

template <size_t N>
void AppendTable(const std::array<uint32_t, N>& inTable, std::vector<Triangle>& ioTriangles)
{
    for (size_t i = 0; i < N; i += 3)
        ioTriangles.push_back({inTable[i], inTable[i + 1], inTable[i + 2]});
}

void AppendTriangles(ObjectKind inKind, std::vector<Triangle>& ioTriangles)
{
    switch (inKind)
    {
    case ObjectKind::Ground:
        for (uint32_t j = 0; j < cGroundQuads; ++j)
            for (uint32_t i = 0; i < cGroundQuads; ++i)
            {
                const uint32_t v00 = j * cGroundSide + i, v10 = v00 + 1, v01 = v00 + cGroundSide,
                               v11 = v01 + 1;
                ioTriangles.push_back({v00, v01, v11});
                ioTriangles.push_back({v00, v11, v10});
            }
        break;
    case ObjectKind::Box:
        AppendTable(cBoxTriangles, ioTriangles);
        break;
    case ObjectKind::Ramp:
        AppendTable(cRampTriangles, ioTriangles);
        break;
    }
}

AABB BoundsOf(const ObjectVertices& inVertices)
{
    AABB bounds;
    for (uint32_t i = 0; i < inVertices.mCount; ++i)
        bounds.Encapsulate(inVertices.mPositions[i]);
    return bounds;
}

/// The cells [outFirst, outLast] of a row of inNumCells that may touch [inMin, inMax]: one more on each side
/// than the division says, for its rounding (the caller tests the cells' exact sides).
void CellRange(float inMin, float inMax, float inCellSize, uint32_t inNumCells, uint32_t& outFirst,
               uint32_t& outLast)
{
    const double last = double(inNumCells - 1);
    outFirst = uint32_t(std::clamp(std::floor(double(inMin) / inCellSize) - 1.0, 0.0, last));
    outLast = uint32_t(std::clamp(std::floor(double(inMax) / inCellSize) + 1.0, 0.0, last));
}

std::string FormatFloat(float inValue)
{
    char text[32];
    std::snprintf(text, sizeof(text), "%.9g", double(inValue));
    return text;
}

/// The level's geometry from its settings alone: every query makes one and recomputes what it needs.
class Generator
{
public:
    explicit Generator(const GeneratedLevelSettings& inSettings)
        : mSettings(inSettings), mGroundStep(inSettings.mCellSize / float(cGroundQuads))
    {
        Dice dice(Mix64(inSettings.mSeed) ^ 0x7465727261696eull); // Its own sequence, apart from the props'
        for (float& phase : mPhases)
            phase = dice.Unit();
    }

    std::optional<ObjectId> Decode(uint64_t inKey) const
    {
        const uint64_t cell = inKey >> GeneratedLevel::cIndexBits;
        const uint64_t index = inKey & ((uint64_t(1) << GeneratedLevel::cIndexBits) - 1);
        if (index > mSettings.mPropsPerCell || cell >= uint64_t(mSettings.mCellsX) * mSettings.mCellsZ)
            return std::nullopt;
        return ObjectId{uint32_t(cell % mSettings.mCellsX), uint32_t(cell / mSettings.mCellsX),
                        uint32_t(index)};
    }

    /// x (or z) of ground grid line inLine. Everything, cell sides included, comes from here, so that the
    /// grounds of neighbouring cells share their edge vertices bit for bit.
    float GridLine(uint32_t inLine) const { return float(inLine) * mGroundStep; }
    /// Cell inCell spans [CellSide(inCell), CellSide(inCell + 1)] in x (or z).
    float CellSide(uint32_t inCell) const { return GridLine(inCell * cGroundQuads); }

    /// Of world x and z alone, so neighbouring cells agree. |height| <= 1.5 + 0.4 + 0.15; slopes under ~21
    /// degrees (a wave's slope is at most 8 x amplitude x frequency), walkable.
    float GroundHeight(float inX, float inZ) const
    {
        return 1.5f * Wave(inX * 0.008f + mPhases[0]) * Wave(inZ * 0.011f + mPhases[1]) +
               0.4f * Wave(inX * 0.031f + inZ * 0.017f + mPhases[2]) +
               0.15f * Wave(inZ * 0.073f - inX * 0.041f + mPhases[3]);
    }

    void MakeVertices(const ObjectId& inId, ObjectVertices& outVertices) const
    {
        if (inId.mIndex == 0)
            MakeGround(inId, outVertices);
        else
            MakeProp(inId, outVertices);
    }

    std::string Name(const ObjectId& inId) const
    {
        const std::string cell = "cell_" + std::to_string(inId.mCellX) + "_" + std::to_string(inId.mCellZ);
        if (inId.mIndex == 0) return cell + "_ground";
        return cell + (IsRamp(inId.mIndex) ? "_ramp_" : "_box_") + std::to_string(inId.mIndex);
    }

private:
    static bool IsRamp(uint32_t inIndex) { return inIndex % cRampEvery == 0; }

    void MakeGround(const ObjectId& inId, ObjectVertices& outVertices) const
    {
        outVertices.mKind = ObjectKind::Ground;
        outVertices.mCount = cGroundSide * cGroundSide;
        for (uint32_t j = 0; j < cGroundSide; ++j)
        {
            const float z = GridLine(inId.mCellZ * cGroundQuads + j);
            for (uint32_t i = 0; i < cGroundSide; ++i)
            {
                const float x = GridLine(inId.mCellX * cGroundQuads + i);
                outVertices.mPositions[j * cGroundSide + i] = Vec3(x, GroundHeight(x, z), z);
            }
        }
    }

    void MakeProp(const ObjectId& inId, ObjectVertices& outVertices) const
    {
        // Hashed from the cell's coordinates, not its key: a larger world keeps a smaller one's props
        Dice dice(
            Mix64(Mix64(Mix64(mSettings.mSeed) ^ (uint64_t(inId.mCellX) << 32 | inId.mCellZ)) ^ inId.mIndex));
        const bool ramp = IsRamp(inId.mIndex);
        float halfX = 0.5f * (ramp ? dice.Between(2.0f, 6.0f) : dice.Between(0.5f, 3.0f)); // Ramp: its length
        float halfZ = 0.5f * (ramp ? dice.Between(1.5f, 3.0f) : dice.Between(0.5f, 3.0f));
        const float heightOrSlope = ramp ? dice.Between(0.15f, 0.55f) : dice.Between(0.5f, 4.0f);

        // Whatever the yaw, the footprint stays within radius of the centre; small cells shrink it to fit
        const float cellSize = mSettings.mCellSize, margin = cCellMargin * cellSize;
        const float maxRadius = 0.5f * cellSize - margin;
        float radius = std::sqrt(halfX * halfX + halfZ * halfZ);
        if (radius > maxRadius)
        {
            const float scale = maxRadius / radius;
            halfX *= scale;
            halfZ *= scale;
            radius = maxRadius;
        }
        const float height = ramp ? 2.0f * halfX * heightOrSlope : heightOrSlope;
        const float minX = CellSide(inId.mCellX), maxX = CellSide(inId.mCellX + 1);
        const float minZ = CellSide(inId.mCellZ), maxZ = CellSide(inId.mCellZ + 1);
        const float room = std::max(0.0f, cellSize - 2.0f * (margin + radius));
        const float centreX = minX + margin + radius + room * dice.Unit();
        const float centreZ = minZ + margin + radius + room * dice.Unit();

        // Yaw as a direction in the unit disc (rejection sampling): sqrt is exact everywhere, cos and sin not
        float cosYaw = 1.0f, sinYaw = 0.0f;
        for (int attempt = 0; attempt < 32; ++attempt)
        {
            const float a = dice.Between(-1.0f, 1.0f), b = dice.Between(-1.0f, 1.0f);
            const float lengthSq = a * a + b * b;
            if (lengthSq > 0.01f && lengthSq <= 1.0f)
            {
                const float length = std::sqrt(lengthSq);
                cosYaw = a / length;
                sinYaw = b / length;
                break;
            }
        }

        // Footprint corner k (bit 0: +x half, bit 1: +z half), clamped to the cell against rounding
        std::array<float, 4> cornerX, cornerZ;
        float lowestGround = GroundHeight(centreX, centreZ);
        for (uint32_t k = 0; k < 4; ++k)
        {
            const float localX = (k & 1) != 0 ? halfX : -halfX, localZ = (k & 2) != 0 ? halfZ : -halfZ;
            cornerX[k] = std::clamp(centreX + cosYaw * localX - sinYaw * localZ, minX, maxX);
            cornerZ[k] = std::clamp(centreZ + sinYaw * localX + cosYaw * localZ, minZ, maxZ);
            lowestGround = std::min(lowestGround, GroundHeight(cornerX[k], cornerZ[k]));
        }
        const float bottom = lowestGround - cEmbedDepth, top = bottom + height;

        for (uint32_t k = 0; k < 4; ++k)
            outVertices.mPositions[k] = Vec3(cornerX[k], bottom, cornerZ[k]);
        if (ramp)
        {
            outVertices.mKind = ObjectKind::Ramp;
            outVertices.mCount = 6;
            outVertices.mPositions[4] = Vec3(cornerX[1], top, cornerZ[1]);
            outVertices.mPositions[5] = Vec3(cornerX[3], top, cornerZ[3]);
        }
        else
        {
            outVertices.mKind = ObjectKind::Box;
            outVertices.mCount = 8;
            for (uint32_t k = 0; k < 4; ++k)
                outVertices.mPositions[4 + k] = Vec3(cornerX[k], top, cornerZ[k]);
        }
    }

    const GeneratedLevelSettings& mSettings;
    float mGroundStep; ///< The cell size / 8: exact, so grid line 8c is exactly the cell size x c
    std::array<float, 4> mPhases;
};

} // namespace

Result<std::unique_ptr<GeneratedLevel>> GeneratedLevel::Create(const GeneratedLevelSettings& inSettings)
{
    const GeneratedLevelSettings& s = inSettings;
    auto invalid = [](const std::string& inWhy)
    { return MakeError(ErrorCode::InvalidArgument, "generated level: " + inWhy); };
    const std::string cells = std::to_string(s.mCellsX) + " x " + std::to_string(s.mCellsZ) + " cells";
    if (s.mCellsX == 0 || s.mCellsZ == 0) return invalid("no cells (" + cells + ")");
    if (s.mCellsX > cMaxCellsPerSide || s.mCellsZ > cMaxCellsPerSide)
        return invalid(cells + ": more than " + std::to_string(cMaxCellsPerSide) + " a side");
    if (!std::isfinite(s.mCellSize) || s.mCellSize < cMinCellSize || s.mCellSize > cMaxCellSize)
        return invalid("a cell size of " + FormatFloat(s.mCellSize) + " m: it must be between " +
                       FormatFloat(cMinCellSize) + " and " + FormatFloat(cMaxCellSize) + " m");
    // The physics world takes no vertex beyond cMaxWorldCoordinate
    if (double(std::max(s.mCellsX, s.mCellsZ)) * s.mCellSize > double(cMaxWorldCoordinate))
        return invalid(cells + " of " + FormatFloat(s.mCellSize) + " m reach beyond " +
                       FormatFloat(cMaxWorldCoordinate) + " m");
    if (s.mPropsPerCell > cMaxPropsPerCell)
        return invalid(std::to_string(s.mPropsPerCell) + " props per cell: at most " +
                       std::to_string(cMaxPropsPerCell));
    // A closed interval of length L touches at most floor(L / size) + 2 cells of a row (both its ends on
    // sides)
    const uint64_t cellsPerBox = uint64_t(std::floor(cMaxQueryBoxSide / s.mCellSize)) + 2;
    const uint64_t maxNear = (uint64_t(1) + s.mPropsPerCell) * std::min<uint64_t>(cellsPerBox, s.mCellsX) *
                             std::min<uint64_t>(cellsPerBox, s.mCellsZ);
    if (maxNear > cMaxObjectsNearLimit)
        return invalid(std::to_string(maxNear) + " objects could be near a tile (" +
                       std::to_string(s.mPropsPerCell) + " props in cells of " + FormatFloat(s.mCellSize) +
                       " m): at most " + std::to_string(cMaxObjectsNearLimit) +
                       "; use fewer props or larger cells");

    std::unique_ptr<GeneratedLevel> level(new GeneratedLevel(s));
    level->mMaxObjectsNear = uint32_t(maxNear);
    const Generator generator(level->mSettings);
    ObjectVertices vertices;
    for (uint32_t cz = 0; cz < s.mCellsZ; ++cz)
        for (uint32_t cx = 0; cx < s.mCellsX; ++cx)
            for (uint32_t index = 0; index <= s.mPropsPerCell; ++index)
            {
                generator.MakeVertices({cx, cz, index}, vertices);
                level->mBounds.Encapsulate(BoundsOf(vertices));
            }
    return level;
}

void GeneratedLevel::FindObjects(const AABB& inBox, std::vector<SourceObject>& ioObjects) const
{
    if (!inBox.Overlaps(mBounds)) return; // Empty and NaN boxes too
    const Generator generator(mSettings);
    uint32_t firstX, lastX, firstZ, lastZ;
    CellRange(inBox.mMin.x(), inBox.mMax.x(), mSettings.mCellSize, mSettings.mCellsX, firstX, lastX);
    CellRange(inBox.mMin.z(), inBox.mMax.z(), mSettings.mCellSize, mSettings.mCellsZ, firstZ, lastZ);
    ObjectVertices vertices;
    for (uint32_t cz = firstZ; cz <= lastZ; ++cz)
    {
        if (generator.CellSide(cz) > inBox.mMax.z() || generator.CellSide(cz + 1) < inBox.mMin.z()) continue;
        for (uint32_t cx = firstX; cx <= lastX; ++cx)
        {
            // Every object lies within its cell's square: a cell the box misses has none the box touches
            if (generator.CellSide(cx) > inBox.mMax.x() || generator.CellSide(cx + 1) < inBox.mMin.x())
                continue;
            for (uint32_t index = 0; index <= mSettings.mPropsPerCell; ++index)
            {
                generator.MakeVertices({cx, cz, index}, vertices);
                const AABB bounds = BoundsOf(vertices);
                if (bounds.Overlaps(inBox)) ioObjects.push_back({MakeKey(cx, cz, index), bounds});
            }
        }
    }
}

Result<navmesh::LevelPart> GeneratedLevel::MakeObject(uint64_t inKey) const
{
    const Generator generator(mSettings);
    const std::optional<ObjectId> id = generator.Decode(inKey);
    if (!id) return MakeError(ErrorCode::InvalidArgument, Describe(inKey));
    ObjectVertices vertices;
    generator.MakeVertices(*id, vertices);
    navmesh::LevelPart part;
    part.mName = generator.Name(*id);
    part.mArea = navmesh::cDefaultArea;
    part.mMesh.mVertices.assign(vertices.mPositions.begin(), vertices.mPositions.begin() + vertices.mCount);
    AppendTriangles(vertices.mKind, part.mMesh.mTriangles);
    return part;
}

Result<SourceBody> GeneratedLevel::MakeBody(uint64_t inKey) const
{
    Result<navmesh::LevelPart> part = MakeObject(inKey);
    if (!part) return part.GetError();
    auto shape = TriangleMeshShape::Create(part.Value().mMesh.mVertices, part.Value().mMesh.mTriangles);
    if (!shape) return MakeError(shape.GetError().mCode, Describe(inKey) + ": " + shape.GetError().mMessage);
    return SourceBody{shape.Value(), part.Value().mArea};
}

std::string GeneratedLevel::Describe(uint64_t inKey) const
{
    const std::optional<ObjectId> id = Generator(mSettings).Decode(inKey);
    if (!id) return "generated level: no object has key " + std::to_string(inKey) + " (unknown)";
    return "generated cell (" + std::to_string(id->mCellX) + ", " + std::to_string(id->mCellZ) + ") object " +
           std::to_string(id->mIndex);
}

std::vector<std::string> GeneratedLevel::GetInputNames() const
{
    return {"generated: seed " + std::to_string(mSettings.mSeed) + ", " + std::to_string(mSettings.mCellsX) +
            " x " + std::to_string(mSettings.mCellsZ) + " cells of " + FormatFloat(mSettings.mCellSize) +
            " m, " + std::to_string(mSettings.mPropsPerCell) + " props per cell"};
}

std::string GeneratedLevel::ToObj() const
{
    const Generator generator(mSettings);
    std::string obj;
    char line[128];
    unsigned long long firstVertex = 1; // OBJ counts vertices from 1, across objects
    ObjectVertices vertices;
    std::vector<Triangle> triangles;
    // Key order: the cells in rows of x, then each cell's objects
    for (uint32_t cz = 0; cz < mSettings.mCellsZ; ++cz)
        for (uint32_t cx = 0; cx < mSettings.mCellsX; ++cx)
            for (uint32_t index = 0; index <= mSettings.mPropsPerCell; ++index)
            {
                const ObjectId id{cx, cz, index};
                generator.MakeVertices(id, vertices);
                obj += "o " + generator.Name(id) + "\n";
                for (uint32_t i = 0; i < vertices.mCount; ++i)
                {
                    const Vec3& v = vertices.mPositions[i];
                    std::snprintf(line, sizeof(line), "v %.9g %.9g %.9g\n", double(v.x()), double(v.y()),
                                  double(v.z()));
                    obj += line;
                }
                triangles.clear();
                AppendTriangles(vertices.mKind, triangles);
                for (const Triangle& t : triangles)
                {
                    std::snprintf(line, sizeof(line), "f %llu %llu %llu\n", firstVertex + t[0],
                                  firstVertex + t[1], firstVertex + t[2]);
                    obj += line;
                }
                firstVertex += vertices.mCount;
            }
    return obj;
}

} // namespace cairn::bake
