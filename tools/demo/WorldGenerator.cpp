// WorldGenerator: the deterministic open world of the streaming demo (see WorldGenerator.h). Every const
// method is safe from any thread: the shapes made in the constructor are immutable and everything else is
// local.

#include "WorldGenerator.h"

#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/ConvexHullShape.h"
#include "cairn/physics/shapes/HeightFieldShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"
#include "common/Mix64.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>

namespace cairn::demo
{
using namespace cairn::physics;

namespace
{

/// Height samples are 1 m apart; tiles are a whole number of metres, so tile edges fall on samples
constexpr float cCellSize = 1.0f;

/// Full box sizes (m) of the shared box shapes; props and bodies pick sizes from this table so that a few
/// thousand shapes made once serve every tile
constexpr float cBoxSizes[] = {0.15f, 0.2f, 0.25f, 0.3f, 0.35f, 0.4f, 0.5f, 0.6f, 0.7f,
                               0.8f,  1.0f, 1.2f,  1.5f, 1.8f,  2.2f, 2.6f, 3.0f};
constexpr int cNumBoxSizes = int(std::size(cBoxSizes));
constexpr int cSize015 = 0, cSize030 = 3, cSize040 = 5, cSize050 = 6, cSize060 = 7, cSize080 = 9,
              cSize100 = 10, cSize120 = 11, cSize150 = 12, cSize180 = 13, cSize220 = 14, cSize300 = 16;

/// Terrain: value noise octaves (period in samples, amplitude in m): hills a few metres high, slopes below
/// about 15 degrees so that props sit well and agents walk anywhere
struct Octave
{
    int64_t mPeriod;
    float mAmplitude;
};
constexpr Octave cOctaves[] = {{128, 4.0f}, {48, 1.8f}, {16, 0.5f}};

/// Player path: z = centre + A sin(2 pi (x - start) / L)
constexpr double cPathAmplitude = 10.0;   ///< m
constexpr double cPathWavelength = 256.0; ///< m
constexpr int cPathSamples = 1024;        ///< Arc-length table entries per wavelength
/// Half the width of the prop-free corridor around the path (m)
constexpr float cCorridorHalfWidth = 3.0f;
/// |dz| overestimates the distance to the sloped path by at most sqrt(1 + slope^2), slope <= 2 pi A / L
/// (0.245): the corridor test scales its width by this so the corridor is at least as wide everywhere
constexpr float cCorridorScale = 1.03f;

/// Clear space between footprints of different clusters: an agent of radius 0.6 m passes through any gap
constexpr float cPropGap = 1.5f;
/// Debris only collides with static bodies: it needs no walking room, only not to start inside a prop
constexpr float cDebrisGap = 0.2f;
/// Footprint grid cell (m): about the size of a typical footprint plus the gap
constexpr float cGridCell = 2.0f;

constexpr float cStaticFriction = 0.7f;
constexpr float cDynamicFriction = 0.6f;

constexpr float cRampLength = 4.0f, cRampWidth = 2.0f, cRampHeight = 1.0f;
constexpr float cArchInner = 2.0f, cArchOuter = 2.8f, cArchLegHeight = 1.2f, cArchDepth = 0.8f;
constexpr int cArchSegments = 10;
constexpr int cNumRocks = 6;
constexpr float cCrateHalf = 0.25f;

using tools::Mix64;

uint64_t Hash(uint64_t inA, uint64_t inB)
{
    return Mix64(Mix64(inA) ^ (inB + 0x9e3779b97f4a7c15ull));
}

/// PCG32 (O'Neill): tiny, fast and fully specified, unlike <random>'s distributions
class Pcg32
{
public:
    Pcg32(uint64_t inSeed, uint64_t inStream) : mInc((inStream << 1) | 1u)
    {
        Next();
        mState += inSeed;
        Next();
    }

    uint32_t Next()
    {
        const uint64_t old = mState;
        mState = old * 6364136223846793005ull + mInc;
        const uint32_t shifted = uint32_t(((old >> 18) ^ old) >> 27);
        const uint32_t rotation = uint32_t(old >> 59);
        return (shifted >> rotation) | (shifted << ((32u - rotation) & 31u));
    }
    /// In [0, 1): 24 random bits, exact in a float
    float Float01() { return float(Next() >> 8) * (1.0f / 16777216.0f); }
    float Range(float inMin, float inMax) { return inMin + (inMax - inMin) * Float01(); }
    /// In [inMin, inMax]
    int Int(int inMin, int inMax)
    {
        const uint64_t span = uint64_t(int64_t(inMax) - int64_t(inMin) + 1);
        return int(int64_t(inMin) + int64_t((uint64_t(Next()) * span) >> 32));
    }

private:
    uint64_t mState = 0;
    uint64_t mInc;
};

int64_t FloorDiv(int64_t inA, int64_t inB)
{
    const int64_t q = inA / inB;
    return (inA % inB != 0 && (inA < 0) != (inB < 0)) ? q - 1 : q;
}

/// Quintic fade: C2 continuous, so the hills have no creases at lattice lines
float Fade(float inT)
{
    return inT * inT * inT * (inT * (inT * 6.0f - 15.0f) + 10.0f);
}

/// Height inside a cell from its corners, on HeightFieldShape's triangles: the cell is split along the
/// (0, 0)-(1, 1) diagonal into (p00, p01, p11) where fz >= fx and (p00, p11, p10) where fx > fz
float CellHeight(float inH00, float inH10, float inH01, float inH11, float inFx, float inFz)
{
    if (inFz >= inFx) return inH00 + inFz * (inH01 - inH00) + inFx * (inH11 - inH01);
    return inH00 + inFx * (inH10 - inH00) + inFz * (inH11 - inH10);
}

/// sin(2 pi inTurns) from arithmetic only (std::sin may differ between C libraries): range reduction to
/// [-1/4, 1/4] turn, then Taylor to x^13 (error below 1e-9)
double DeterministicSin(double inTurns)
{
    double r = inTurns - std::floor(inTurns + 0.5); // [-0.5, 0.5)
    if (r > 0.25)
        r = 0.5 - r;
    else if (r < -0.25)
        r = -0.5 - r;
    const double x = r * 6.283185307179586;
    const double x2 = x * x;
    return x * (1.0 + x2 * (-1.0 / 6.0 +
                            x2 * (1.0 / 120.0 +
                                  x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362880.0 + x2 * (-1.0 / 39916800.0 +
                                                                                     x2 / 6227020800.0))))));
}

double DeterministicCos(double inTurns)
{
    return DeterministicSin(inTurns + 0.25);
}

/// A rotation about +y, with the cosine and sine of its angle for rotating footprints in 2D
struct Yaw
{
    float mCos = 1.0f;
    float mSin = 0.0f;
    Quat mRotation = Quat::Identity();

    /// Local (x, z) to the parent's (x, z): the same as mRotation * (x, 0, z)
    void Rotate(float inX, float inZ, float& outX, float& outZ) const
    {
        outX = inX * mCos + inZ * mSin;
        outZ = -inX * mSin + inZ * mCos;
    }
};

/// A point in the unit disc, by rejection (no trigonometry); the centre after 64 misses (never in practice)
void RandomInDisc(Pcg32& ioRandom, float& outX, float& outZ)
{
    for (int i = 0; i < 64; ++i)
    {
        outX = ioRandom.Range(-1.0f, 1.0f);
        outZ = ioRandom.Range(-1.0f, 1.0f);
        if (outX * outX + outZ * outZ <= 1.0f) return;
    }
    outX = outZ = 0.0f;
}

/// A uniformly random yaw: a random direction in the disc, normalised, is (cos, sin) of the half angle
Yaw RandomYaw(Pcg32& ioRandom)
{
    for (int i = 0; i < 64; ++i)
    {
        const float a = ioRandom.Range(-1.0f, 1.0f), b = ioRandom.Range(-1.0f, 1.0f);
        const float lengthSq = a * a + b * b;
        if (lengthSq < 0.01f || lengthSq > 1.0f) continue;
        const float inverse = 1.0f / std::sqrt(lengthSq);
        const float c = a * inverse, s = b * inverse;
        Yaw yaw;
        yaw.mCos = c * c - s * s;
        yaw.mSin = 2.0f * c * s;
        yaw.mRotation = Quat(c, 0.0f, s, 0.0f);
        return yaw;
    }
    return {};
}

/// Footprints (circles on the x-z plane, tile-local) in a uniform grid, for the spacing test
class FootprintGrid
{
public:
    explicit FootprintGrid(float inSize)
        : mCellsPerSide(std::max(1, int(std::ceil(inSize / cGridCell)))),
          mHead(size_t(mCellsPerSide) * size_t(mCellsPerSide), -1)
    {
    }

    /// True when the circle keeps inGap clear of every footprint
    bool IsFree(float inX, float inZ, float inRadius, float inGap) const
    {
        const float reach = inRadius + inGap + mMaxRadius;
        const int x0 = CellOf(inX - reach), x1 = CellOf(inX + reach);
        const int z0 = CellOf(inZ - reach), z1 = CellOf(inZ + reach);
        for (int z = z0; z <= z1; ++z)
            for (int x = x0; x <= x1; ++x)
                for (int32_t i = mHead[size_t(x + z * mCellsPerSide)]; i >= 0; i = mItems[size_t(i)].mNext)
                {
                    const Item& item = mItems[size_t(i)];
                    const float dx = item.mX - inX, dz = item.mZ - inZ;
                    const float limit = item.mRadius + inRadius + inGap;
                    if (dx * dx + dz * dz < limit * limit) return false;
                }
        return true;
    }

    void Add(float inX, float inZ, float inRadius)
    {
        const size_t cell = size_t(CellOf(inX) + CellOf(inZ) * mCellsPerSide);
        mItems.push_back({inX, inZ, inRadius, mHead[cell]});
        mHead[cell] = int32_t(mItems.size() - 1);
        mMaxRadius = std::max(mMaxRadius, inRadius);
    }

private:
    struct Item
    {
        float mX;
        float mZ;
        float mRadius;
        int32_t mNext; ///< Next item in the same cell, -1 at the end
    };

    int CellOf(float inV) const
    {
        return std::clamp(int(std::floor(inV * (1.0f / cGridCell))), 0, mCellsPerSide - 1);
    }

    int mCellsPerSide;
    float mMaxRadius = 0.0f;
    std::vector<int32_t> mHead; ///< First item per cell, -1 for none
    std::vector<Item> mItems;
};

} // namespace

struct WorldGenerator::Candidate
{
    const ShapeRef* mShape = nullptr; ///< One of the generator's shared shapes
    Vec3 mPosition = Vec3::Zero();    ///< Tile-local
    Quat mRotation = Quat::Identity();
    float mFootX = 0.0f; ///< Footprint circle, tile-local
    float mFootZ = 0.0f;
    float mFootRadius = 0.0f;
};

struct WorldGenerator::TileContext
{
    TileContext(int inCells, float inOriginX, float inOriginZ, uint64_t inSeed)
        : mCells(inCells), mSize(float(inCells) * cCellSize), mOriginX(inOriginX), mOriginZ(inOriginZ),
          mHeights(size_t(inCells + 1) * size_t(inCells + 1)), mRandom(inSeed, 1), mGrid(mSize)
    {
    }

    int mCells;     ///< Cells per side (samples - 1)
    float mSize;    ///< m
    float mOriginX; ///< World position of tile-local (0, 0)
    float mOriginZ;
    std::vector<float> mHeights; ///< The height field's samples, row-major
    Pcg32 mRandom;
    FootprintGrid mGrid;

    /// Terrain height at a tile-local point (clamped to the tile), the same surface as the height field
    float Height(float inX, float inZ) const
    {
        const float u = std::clamp(inX * (1.0f / cCellSize), 0.0f, float(mCells));
        const float w = std::clamp(inZ * (1.0f / cCellSize), 0.0f, float(mCells));
        const int x = std::min(int(u), mCells - 1), z = std::min(int(w), mCells - 1);
        const size_t stride = size_t(mCells + 1), i = size_t(x) + size_t(z) * stride;
        return CellHeight(mHeights[i], mHeights[i + 1], mHeights[i + stride], mHeights[i + stride + 1],
                          u - float(x), w - float(z));
    }

    /// Lowest (or highest) terrain under the centre and corners of a yawed rectangle: a box whose bottom is
    /// the lowest is sunk into the ground everywhere, never floating over a dip
    float Ground(float inX, float inZ, float inHalfX, float inHalfZ, const Yaw& inYaw, bool inHighest) const
    {
        float result = Height(inX, inZ);
        for (int corner = 0; corner < 4; ++corner)
        {
            float dx, dz;
            inYaw.Rotate(corner & 1 ? inHalfX : -inHalfX, corner & 2 ? inHalfZ : -inHalfZ, dx, dz);
            const float h = Height(inX + dx, inZ + dz);
            result = inHighest ? std::max(result, h) : std::min(result, h);
        }
        return result;
    }

    /// Mean terrain normal over a square of half size inHalf (central differences)
    Vec3 Normal(float inX, float inZ, float inHalf) const
    {
        const float dx = (Height(inX + inHalf, inZ) - Height(inX - inHalf, inZ)) / (2.0f * inHalf);
        const float dz = (Height(inX, inZ + inHalf) - Height(inX, inZ - inHalf)) / (2.0f * inHalf);
        return Vec3(-dx, 1.0f, -dz).normalized();
    }

    /// A box of full sizes cBoxSizes[inSizes[i]] centred at (inX, inZ) with its bottom at inBottom; returns
    /// its top
    float AddBox(const WorldGenerator& inGenerator, const std::array<int, 3>& inSizes, float inX, float inZ,
                 float inBottom, const Yaw& inYaw, std::vector<Candidate>& ioCandidates) const
    {
        const float hx = 0.5f * cBoxSizes[inSizes[0]], hy = 0.5f * cBoxSizes[inSizes[1]];
        const float hz = 0.5f * cBoxSizes[inSizes[2]];
        Candidate candidate;
        candidate.mShape = &inGenerator.GetBox(inSizes[0], inSizes[1], inSizes[2]);
        candidate.mPosition = Vec3(inX, inBottom + hy, inZ);
        candidate.mRotation = inYaw.mRotation;
        candidate.mFootX = inX;
        candidate.mFootZ = inZ;
        candidate.mFootRadius = std::sqrt(hx * hx + hz * hz);
        ioCandidates.push_back(candidate);
        return inBottom + 2.0f * hy;
    }

    /// A box sunk slightly into the terrain under it; returns its top
    float AddBoxOnGround(const WorldGenerator& inGenerator, const std::array<int, 3>& inSizes, float inX,
                         float inZ, const Yaw& inYaw, std::vector<Candidate>& ioCandidates) const
    {
        const float hx = 0.5f * cBoxSizes[inSizes[0]], hz = 0.5f * cBoxSizes[inSizes[2]];
        const float bottom = Ground(inX, inZ, hx, hz, inYaw, false) - 0.05f;
        return AddBox(inGenerator, inSizes, inX, inZ, bottom, inYaw, ioCandidates);
    }

    /// True when every candidate lies inside the tile (half a gap from its edges, so that clusters of two
    /// tiles keep the gap too), off the player's corridor and inGap away from every other footprint
    bool Fits(const WorldGenerator& inGenerator, const std::vector<Candidate>& inCandidates,
              float inGap) const
    {
        const float margin = 0.5f * inGap;
        for (const Candidate& candidate : inCandidates)
        {
            const float x = candidate.mFootX, z = candidate.mFootZ, r = candidate.mFootRadius;
            if (*candidate.mShape == nullptr) return false;
            if (x - r < margin || z - r < margin || x + r > mSize - margin || z + r > mSize - margin)
                return false;
            if (!inGenerator.IsClearOfPath(*this, x, z, r) || !mGrid.IsFree(x, z, r, inGap)) return false;
        }
        return true;
    }

    BodyCreationSettings MakeBody(const Candidate& inCandidate, MotionType inMotion,
                                  ObjectLayer inLayer) const
    {
        BodyCreationSettings settings;
        settings.mShape = *inCandidate.mShape;
        settings.mPosition = Vec3(mOriginX + inCandidate.mPosition.x(), inCandidate.mPosition.y(),
                                  mOriginZ + inCandidate.mPosition.z());
        settings.mRotation = inCandidate.mRotation;
        settings.mMotionType = inMotion;
        settings.mObjectLayer = inLayer;
        settings.mFriction = inMotion == MotionType::Static ? cStaticFriction : cDynamicFriction;
        settings.mNavMeshArea = 0;
        return settings;
    }
};

WorldGenerator::WorldGenerator(const WorldSettings& inSettings) : mSettings(inSettings)
{
    // Whole metres: the 1 m height samples then fall exactly on tile edges and neighbours share them
    const float size = std::isfinite(mSettings.mTileSize) ? mSettings.mTileSize : 64.0f;
    mSettings.mTileSize = std::clamp(std::round(size), 8.0f, 1024.0f);
    mSettings.mPropsPerTile = std::clamp(mSettings.mPropsPerTile, 0, 100000);
    mSettings.mDynamicPerTile = std::clamp(mSettings.mDynamicPerTile, 0, 100000);
    mSettings.mBuildingsPerTile = std::clamp(mSettings.mBuildingsPerTile, 0, 64);
    if (!std::isfinite(mSettings.mPlayerSpeed)) mSettings.mPlayerSpeed = 8.0f;
    mSettings.mPlayerSpeed = std::clamp(mSettings.mPlayerSpeed, -1000.0f, 1000.0f);
    mSeedHash = Mix64(mSettings.mSeed ^ 0x636169726e776f72ull);

    // Boxes: every size combination (17^3, about 0.3 MB), so that no tile allocates a box shape
    mBoxes.resize(size_t(cNumBoxSizes) * cNumBoxSizes * cNumBoxSizes);
    for (int z = 0; z < cNumBoxSizes; ++z)
        for (int y = 0; y < cNumBoxSizes; ++y)
            for (int x = 0; x < cNumBoxSizes; ++x)
            {
                auto box = BoxShape::Create(0.5f * Vec3(cBoxSizes[x], cBoxSizes[y], cBoxSizes[z]));
                if (box) mBoxes[size_t(x + cNumBoxSizes * (y + cNumBoxSizes * z))] = std::move(box).Value();
            }

    // Rocks: 8 to 12 points near an ellipsoid's surface; a failed hull (coplanar draw) is drawn again
    Pcg32 random(Hash(mSeedHash, 0x726f636b), 2);
    for (int rock = 0; rock < cNumRocks; ++rock)
        for (int attempt = 0; attempt < 8; ++attempt)
        {
            const Vec3 radii(random.Range(0.4f, 1.1f), random.Range(0.3f, 0.8f), random.Range(0.4f, 1.1f));
            std::vector<Vec3> points;
            const int count = random.Int(8, 12);
            while (int(points.size()) < count)
            {
                const Vec3 direction(random.Range(-1.0f, 1.0f), random.Range(-1.0f, 1.0f),
                                     random.Range(-1.0f, 1.0f));
                const float lengthSq = direction.squaredNorm();
                if (lengthSq < 0.04f || lengthSq > 1.0f) continue;
                points.push_back(direction.cwiseProduct(radii) *
                                 (random.Range(0.75f, 1.0f) / std::sqrt(lengthSq)));
            }
            auto hull = ConvexHullShape::Create(points);
            if (!hull) continue;
            Rock made;
            made.mBottom = hull.Value()->GetLocalBounds().mMin.y();
            for (const Vec3& v : hull.Value()->GetVertices())
                made.mRadius = std::max(made.mRadius, std::sqrt(v.x() * v.x() + v.z() * v.z()));
            made.mShape = std::move(hull).Value();
            mRocks.push_back(std::move(made));
            break;
        }

    // Meshes are built from quads counter-clockwise seen from outside
    std::vector<Vec3> vertices;
    std::vector<std::array<uint32_t, 3>> triangles;
    auto quad = [&](uint32_t inA, uint32_t inB, uint32_t inC, uint32_t inD)
    {
        triangles.push_back({inA, inB, inC});
        triangles.push_back({inA, inC, inD});
    };

    // Ramp: a wedge rising along +x from the ground at x = -L/2 to cRampHeight at x = +L/2; origin at the
    // middle of its bottom
    {
        const float hx = 0.5f * cRampLength, hz = 0.5f * cRampWidth;
        vertices = {{-hx, 0.0f, -hz}, {hx, 0.0f, -hz},        {hx, 0.0f, hz},
                    {-hx, 0.0f, hz},  {hx, cRampHeight, -hz}, {hx, cRampHeight, hz}};
        triangles.clear();
        quad(0, 1, 2, 3); // Bottom
        quad(1, 4, 5, 2); // High end
        quad(0, 3, 5, 4); // Slope
        triangles.push_back({0, 4, 1});
        triangles.push_back({3, 2, 5});
        if (auto ramp = TriangleMeshShape::Create(vertices, triangles)) mRamp = std::move(ramp).Value();
    }

    // Arch: a half ring on two legs, swept along the profile from the left leg's foot over the top to the
    // right one's; origin at the middle of its base. Each profile point has inner and outer vertices, front
    // (+z) and back
    {
        std::vector<std::array<float, 4>> profile; // Inner x, y, outer x, y
        profile.push_back({-cArchInner, 0.0f, -cArchOuter, 0.0f});
        for (int k = 0; k <= cArchSegments; ++k)
        {
            const double turns = 0.5 - 0.5 * double(k) / double(cArchSegments); // Half a turn down to 0
            const float c = float(DeterministicCos(turns)), s = float(DeterministicSin(turns));
            profile.push_back({cArchInner * c, cArchLegHeight + cArchInner * s, cArchOuter * c,
                               cArchLegHeight + cArchOuter * s});
        }
        profile.push_back({cArchInner, 0.0f, cArchOuter, 0.0f});
        const float hz = 0.5f * cArchDepth;
        vertices.clear();
        triangles.clear();
        for (const auto& p : profile)
        {
            vertices.push_back({p[0], p[1], hz});
            vertices.push_back({p[0], p[1], -hz});
            vertices.push_back({p[2], p[3], hz});
            vertices.push_back({p[2], p[3], -hz});
        }
        // Vertex i of a profile point: +0 inner front, +1 inner back, +2 outer front, +3 outer back
        for (uint32_t i = 0; i + 1 < uint32_t(profile.size()); ++i)
        {
            const uint32_t a = 4 * i, b = 4 * (i + 1);
            quad(a + 0, b + 0, b + 2, a + 2); // Front
            quad(a + 1, a + 3, b + 3, b + 1); // Back
            quad(a + 2, b + 2, b + 3, a + 3); // Outer
            quad(a + 0, a + 1, b + 1, b + 0); // Inner
        }
        const uint32_t last = 4 * uint32_t(profile.size() - 1);
        quad(0, 2, 3, 1);                             // Left foot
        quad(last + 0, last + 1, last + 3, last + 2); // Right foot
        if (auto arch = TriangleMeshShape::Create(vertices, triangles)) mArch = std::move(arch).Value();
    }

    // Arc length along one wavelength of the path, so that the player moves at mPlayerSpeed along the curve
    const double start = 0.5 * double(mSettings.mTileSize);
    const double step = cPathWavelength / cPathSamples;
    mPathArcs.resize(cPathSamples + 1);
    mPathArcs[0] = 0.0;
    double previous = PathZ(start);
    for (int i = 1; i <= cPathSamples; ++i)
    {
        const double z = PathZ(start + double(i) * step);
        mPathArcs[size_t(i)] =
            mPathArcs[size_t(i - 1)] + std::sqrt(step * step + (z - previous) * (z - previous));
        previous = z;
    }
}

const ShapeRef& WorldGenerator::GetBox(int inX, int inY, int inZ) const
{
    return mBoxes[size_t(inX + cNumBoxSizes * (inY + cNumBoxSizes * inZ))];
}

float WorldGenerator::SampleHeight(int64_t inX, int64_t inZ) const
{
    float height = 0.0f;
    uint64_t octaveSeed = mSeedHash;
    for (const Octave& octave : cOctaves)
    {
        octaveSeed = Mix64(octaveSeed + 1);
        const int64_t period = octave.mPeriod;
        const int64_t cx = FloorDiv(inX, period), cz = FloorDiv(inZ, period);
        // Exact integer remainders over the period, so every tile computes a shared sample identically
        const float fx = Fade(float(inX - cx * period) / float(period));
        const float fz = Fade(float(inZ - cz * period) / float(period));
        auto lattice = [&](int64_t inCx, int64_t inCz)
        {
            // 24 bits to [-1, 1), exact in a float
            const uint64_t h = Mix64(Mix64(octaveSeed ^ uint64_t(inCx)) ^ uint64_t(inCz));
            return float(h >> 40) * (2.0f / 16777216.0f) - 1.0f;
        };
        const float v00 = lattice(cx, cz), v10 = lattice(cx + 1, cz);
        const float v01 = lattice(cx, cz + 1), v11 = lattice(cx + 1, cz + 1);
        const float a = v00 + fx * (v10 - v00), b = v01 + fx * (v11 - v01);
        height += octave.mAmplitude * (a + fz * (b - a));
    }
    return height;
}

double WorldGenerator::PathZ(double inX) const
{
    const double start = 0.5 * double(mSettings.mTileSize);
    return start + cPathAmplitude * DeterministicSin((inX - start) / cPathWavelength);
}

bool WorldGenerator::IsClearOfPath(const TileContext& inContext, float inX, float inZ, float inRadius) const
{
    const double x = double(inContext.mOriginX) + double(inX), z = double(inContext.mOriginZ) + double(inZ);
    return std::abs(z - PathZ(x)) >= double((cCorridorHalfWidth + inRadius) * cCorridorScale);
}

float WorldGenerator::GetTerrainHeight(float inX, float inZ) const
{
    if (!std::isfinite(inX) || !std::isfinite(inZ)) return 0.0f;
    // The clamp keeps the sample index in an int64 (such points are far beyond the engine's range anyway)
    const float u = std::clamp(inX / cCellSize, -1.0e15f, 1.0e15f);
    const float w = std::clamp(inZ / cCellSize, -1.0e15f, 1.0e15f);
    const float fu = std::floor(u), fw = std::floor(w);
    const int64_t x = int64_t(fu), z = int64_t(fw);
    return CellHeight(SampleHeight(x, z), SampleHeight(x + 1, z), SampleHeight(x, z + 1),
                      SampleHeight(x + 1, z + 1), u - fu, w - fw);
}

Vec3 WorldGenerator::GetPlayerPosition(float inSeconds) const
{
    const double start = 0.5 * double(mSettings.mTileSize);
    const double period = mPathArcs.back();
    double distance = double(mSettings.mPlayerSpeed) * double(inSeconds);
    // Beyond 2e6 m there is no world the engine accepts: stop there rather than lose all precision
    distance = std::isfinite(distance) ? std::clamp(distance, -2.0e6, 2.0e6) : 0.0;
    const double periods = std::floor(distance / period);
    const double along = std::clamp(distance - periods * period, 0.0, period);
    const size_t after =
        size_t(std::upper_bound(mPathArcs.begin(), mPathArcs.end(), along) - mPathArcs.begin());
    const size_t i = std::clamp(after, size_t(1), size_t(cPathSamples)) - 1;
    const double segment = mPathArcs[i + 1] - mPathArcs[i];
    const double fraction = segment > 0.0 ? std::clamp((along - mPathArcs[i]) / segment, 0.0, 1.0) : 0.0;
    const double x =
        start + periods * cPathWavelength + (double(i) + fraction) * (cPathWavelength / cPathSamples);
    const float px = float(x), pz = float(PathZ(x));
    return Vec3(px, GetTerrainHeight(px, pz), pz);
}

WorldTile WorldGenerator::TileAt(float inX, float inZ) const
{
    auto tileOf = [&](float inV)
    {
        if (std::isnan(inV)) return int32_t(0);
        const double tile = std::floor(double(inV) / double(mSettings.mTileSize));
        return int32_t(std::clamp(tile, double(std::numeric_limits<int32_t>::min()),
                                  double(std::numeric_limits<int32_t>::max())));
    };
    return {tileOf(inX), tileOf(inZ)};
}

TileContent WorldGenerator::GenerateTile(const WorldTile& inTile, bool inWithDynamic) const
{
    const int cells = int(mSettings.mTileSize / cCellSize);
    const int64_t firstX = int64_t(inTile.mX) * cells, firstZ = int64_t(inTile.mZ) * cells;
    const uint64_t tileSeed =
        Hash(Hash(mSeedHash, uint64_t(int64_t(inTile.mX))), uint64_t(int64_t(inTile.mZ)));
    TileContext context(cells, float(double(firstX) * cCellSize), float(double(firstZ) * cCellSize),
                        tileSeed);

    // Heights from world sample indices: the edge samples two tiles share come out identical
    const int samples = cells + 1;
    for (int z = 0; z < samples; ++z)
        for (int x = 0; x < samples; ++x)
            context.mHeights[size_t(x + z * samples)] = SampleHeight(firstX + x, firstZ + z);

    TileContent content;
    // Cannot fail (finite heights, valid sizes); a null shape would make CreateBody fail, not crash
    if (auto field =
            HeightFieldShape::Create(uint32_t(samples), uint32_t(samples), cCellSize, context.mHeights))
        content.mTerrain.mShape = std::move(field).Value();
    content.mTerrain.mPosition =
        Vec3(context.mOriginX, 0.0f, context.mOriginZ); // Sample (0, 0) at the corner
    content.mTerrain.mMotionType = MotionType::Static;
    content.mTerrain.mObjectLayer = Layers::cStatic;
    content.mTerrain.mFriction = cStaticFriction;
    content.mTerrain.mNavMeshArea = 0;

    // Huts, then props; dynamic bodies draw from a stream of their own after them, so props are the same at
    // every LOD
    AddBuildings(context, tileSeed, content.mProps, content.mDoors);
    AddProps(context, content.mProps);
    if (inWithDynamic) AddDynamic(context, content.mDynamic);
    return content;
}

void WorldGenerator::AddBuildings(TileContext& ioContext, uint64_t inTileSeed,
                                  std::vector<BodyCreationSettings>& outWalls,
                                  std::vector<DoorSpec>& outDoors) const
{
    Pcg32 random(Hash(inTileSeed, 0x687574), 4);
    const float radius = cBuildingFootprintRadius;
    const auto ground = [&](float inX, float inZ)
    { return ioContext.Height(inX - ioContext.mOriginX, inZ - ioContext.mOriginZ); };
    std::vector<Candidate> footprint(1);
    footprint[0].mShape = &GetBox(0, 0, 0); // Fits asks for a shape; only the footprint matters here
    footprint[0].mFootRadius = radius;
    // A handful of tries each: a tile with hills everywhere, or a small one, gets fewer huts
    for (int tries = 0, built = 0;
         built < mSettings.mBuildingsPerTile && tries < 20 * mSettings.mBuildingsPerTile; ++tries)
    {
        const float x = random.Range(radius, ioContext.mSize - radius);
        const float z = random.Range(radius, ioContext.mSize - radius);
        const Yaw yaw = RandomYaw(random);
        const float period = random.Range(10.0f, 14.0f), phase = random.Range(0.0f, period);
        footprint[0].mFootX = x;
        footprint[0].mFootZ = z;
        if (!ioContext.Fits(*this, footprint, cPropGap)) continue;
        const BuildingSite site{ioContext.mOriginX + x, ioContext.mOriginZ + z, yaw.mCos, yaw.mSin,
                                yaw.mRotation};
        float lowest, highest;
        GroundRange(site, ground, lowest, highest);
        if (highest - lowest > cBuildingMaxGroundRise) continue;
        DoorSpec door = MakeBuilding(mBuildingShapes, site, ground, lowest, cStaticFriction, outWalls);
        door.mPeriod = period;
        door.mPhase = phase;
        outDoors.push_back(std::move(door));
        ioContext.mGrid.Add(x, z, radius);
        ++built;
    }
}

void WorldGenerator::AddProps(TileContext& ioContext, std::vector<BodyCreationSettings>& outProps) const
{
    const size_t target = size_t(mSettings.mPropsPerTile) + outProps.size();
    outProps.reserve(target);
    std::vector<Candidate> candidates;
    candidates.reserve(32);
    Pcg32& random = ioContext.mRandom;
    // Clusters hold about 7 props; once the tile fills up most tries fail: this bounds the time of a tile
    const int maxTries = 4 * mSettings.mPropsPerTile + 64;
    for (int tries = 0; tries < maxTries && outProps.size() < target; ++tries)
    {
        const float x = random.Range(0.0f, ioContext.mSize), z = random.Range(0.0f, ioContext.mSize);
        const float kind = random.Float01();
        // A cheap look at the centre first: a taken spot skips building the cluster
        if (!ioContext.mGrid.IsFree(x, z, 0.3f, cPropGap)) continue;
        candidates.clear();
        if (kind < 0.30f)
            MakeRubble(ioContext, x, z, candidates);
        else if (kind < 0.55f)
            MakePile(ioContext, x, z, candidates);
        else if (kind < 0.70f)
            MakeWall(ioContext, x, z, candidates);
        else if (kind < 0.90f)
            MakeRocks(ioContext, x, z, candidates);
        else if (kind < 0.95f)
            MakeRamp(ioContext, x, z, candidates);
        else
            MakeArch(ioContext, x, z, candidates);
        if (!ioContext.Fits(*this, candidates, cPropGap)) continue;
        // The last cluster may be cut short: members come base first, so nothing is left floating
        const size_t count = std::min(candidates.size(), target - outProps.size());
        for (size_t i = 0; i < count; ++i)
        {
            const Candidate& candidate = candidates[i];
            ioContext.mGrid.Add(candidate.mFootX, candidate.mFootZ, candidate.mFootRadius);
            outProps.push_back(ioContext.MakeBody(candidate, MotionType::Static, Layers::cStatic));
        }
    }
}

void WorldGenerator::MakeRubble(TileContext& ioContext, float inX, float inZ,
                                std::vector<Candidate>& ioCandidates) const
{
    Pcg32& random = ioContext.mRandom;
    const float spread = random.Range(1.0f, 2.2f);
    const int count = random.Int(6, 12);
    for (int i = 0; i < count; ++i)
    {
        float dx, dz;
        RandomInDisc(random, dx, dz);
        const std::array<int, 3> sizes = {random.Int(cSize030, cSize080), random.Int(cSize030, cSize080),
                                          random.Int(cSize030, cSize080)};
        const Yaw yaw = RandomYaw(random);
        ioContext.AddBoxOnGround(*this, sizes, inX + dx * spread, inZ + dz * spread, yaw, ioCandidates);
    }
}

void WorldGenerator::MakePile(TileContext& ioContext, float inX, float inZ,
                              std::vector<Candidate>& ioCandidates) const
{
    Pcg32& random = ioContext.mRandom;
    const Yaw yaw = RandomYaw(random);
    const std::array<int, 3> base = {random.Int(cSize120, cSize300), random.Int(cSize080, cSize180),
                                     random.Int(cSize120, cSize300)};
    const float hx = 0.5f * cBoxSizes[base[0]], hz = 0.5f * cBoxSizes[base[2]];
    const float top = ioContext.AddBoxOnGround(*this, base, inX, inZ, yaw, ioCandidates);
    // Smaller boxes on the base, inside its top face
    for (int i = random.Int(1, 3); i > 0; --i)
    {
        const std::array<int, 3> sizes = {random.Int(cSize050, cSize100), random.Int(cSize050, cSize100),
                                          random.Int(cSize050, cSize100)};
        const float roomX = std::max(0.0f, hx - 0.5f * cBoxSizes[sizes[0]]);
        const float roomZ = std::max(0.0f, hz - 0.5f * cBoxSizes[sizes[2]]);
        float dx, dz;
        yaw.Rotate(random.Range(-roomX, roomX), random.Range(-roomZ, roomZ), dx, dz);
        ioContext.AddBox(*this, sizes, inX + dx, inZ + dz, top, yaw, ioCandidates);
    }
    // Small boxes against its sides
    for (int i = random.Int(2, 5); i > 0; --i)
    {
        const std::array<int, 3> sizes = {random.Int(cSize030, cSize080), random.Int(cSize030, cSize080),
                                          random.Int(cSize030, cSize080)};
        float dx, dz;
        RandomInDisc(random, dx, dz);
        const float length = std::sqrt(dx * dx + dz * dz);
        if (length < 0.05f) continue;
        const float distance = random.Range(std::min(hx, hz), std::max(hx, hz)) +
                               0.5f * std::max(cBoxSizes[sizes[0]], cBoxSizes[sizes[2]]);
        const float scale = distance / length;
        ioContext.AddBoxOnGround(*this, sizes, inX + dx * scale, inZ + dz * scale, RandomYaw(random),
                                 ioCandidates);
    }
}

void WorldGenerator::MakeWall(TileContext& ioContext, float inX, float inZ,
                              std::vector<Candidate>& ioCandidates) const
{
    Pcg32& random = ioContext.mRandom;
    const Yaw yaw = RandomYaw(random);
    const int count = random.Int(4, 8);
    const int width = random.Int(cSize060, cSize100), depth = random.Int(cSize040, cSize060);
    const float step = cBoxSizes[width];
    const float first = -0.5f * step * float(count - 1);
    for (int i = 0; i < count; ++i)
    {
        // Blocks follow the terrain, each with its own height: a ruined wall
        float dx, dz;
        yaw.Rotate(first + step * float(i), 0.0f, dx, dz);
        const int height = random.Int(cSize080, cSize220);
        const float top =
            ioContext.AddBoxOnGround(*this, {width, height, depth}, inX + dx, inZ + dz, yaw, ioCandidates);
        if (random.Float01() < 0.3f && cBoxSizes[height] <= 1.5f)
            ioContext.AddBox(*this, {width, random.Int(cSize050, cSize100), depth}, inX + dx, inZ + dz, top,
                             yaw, ioCandidates);
    }
}

void WorldGenerator::MakeRocks(TileContext& ioContext, float inX, float inZ,
                               std::vector<Candidate>& ioCandidates) const
{
    if (mRocks.empty())
    {
        MakeRubble(ioContext, inX, inZ, ioCandidates);
        return;
    }
    Pcg32& random = ioContext.mRandom;
    const float spread = random.Range(0.6f, 1.8f);
    for (int i = random.Int(3, 7); i > 0; --i)
    {
        const Rock& rock = mRocks[size_t(random.Int(0, int(mRocks.size()) - 1))];
        float dx, dz;
        RandomInDisc(random, dx, dz);
        const float x = inX + dx * spread, z = inZ + dz * spread;
        const Yaw yaw = RandomYaw(random);
        // Sunk by 10 cm below the lowest ground near it: rocks look bedded, not dropped
        const float ground = ioContext.Ground(x, z, 0.7f * rock.mRadius, 0.7f * rock.mRadius, Yaw(), false);
        Candidate candidate;
        candidate.mShape = &rock.mShape;
        candidate.mPosition = Vec3(x, ground - rock.mBottom - 0.1f, z);
        candidate.mRotation = yaw.mRotation;
        candidate.mFootX = x;
        candidate.mFootZ = z;
        candidate.mFootRadius = rock.mRadius;
        ioCandidates.push_back(candidate);
    }
}

void WorldGenerator::MakeRamp(TileContext& ioContext, float inX, float inZ,
                              std::vector<Candidate>& ioCandidates) const
{
    Pcg32& random = ioContext.mRandom;
    const Yaw yaw = RandomYaw(random);
    // A platform box at the high end, its top level with the ramp's
    const std::array<int, 3> platform = {cSize220, cSize150, cSize220};
    const float platformHalf = 0.5f * cBoxSizes[cSize220];
    float px, pz;
    yaw.Rotate(0.5f * cRampLength + platformHalf, 0.0f, px, pz);
    px += inX;
    pz += inZ;
    const float bottom =
        std::min(ioContext.Ground(inX, inZ, 0.5f * cRampLength, 0.5f * cRampWidth, yaw, false),
                 ioContext.Ground(px, pz, platformHalf, platformHalf, yaw, false)) -
        0.05f;
    Candidate ramp;
    ramp.mShape = &mRamp;
    ramp.mPosition = Vec3(inX, bottom, inZ);
    ramp.mRotation = yaw.mRotation;
    ramp.mFootX = inX;
    ramp.mFootZ = inZ;
    ramp.mFootRadius = 0.5f * std::sqrt(cRampLength * cRampLength + cRampWidth * cRampWidth);
    ioCandidates.push_back(ramp);
    ioContext.AddBox(*this, platform, px, pz, bottom + cRampHeight - cBoxSizes[platform[1]], yaw,
                     ioCandidates);
}

void WorldGenerator::MakeArch(TileContext& ioContext, float inX, float inZ,
                              std::vector<Candidate>& ioCandidates) const
{
    Pcg32& random = ioContext.mRandom;
    const Yaw yaw = RandomYaw(random);
    // Legs sunk 0.3 m below the lowest ground under either foot; the opening stays over 2.5 m high
    const float legX = 0.5f * (cArchInner + cArchOuter), legHalf = 0.5f * (cArchOuter - cArchInner);
    float lx, lz, rx, rz;
    yaw.Rotate(-legX, 0.0f, lx, lz);
    yaw.Rotate(legX, 0.0f, rx, rz);
    const float bottom =
        std::min(ioContext.Ground(inX + lx, inZ + lz, legHalf, 0.5f * cArchDepth, yaw, false),
                 ioContext.Ground(inX + rx, inZ + rz, legHalf, 0.5f * cArchDepth, yaw, false)) -
        0.3f;
    Candidate arch;
    arch.mShape = &mArch;
    arch.mPosition = Vec3(inX, bottom, inZ);
    arch.mRotation = yaw.mRotation;
    arch.mFootX = inX;
    arch.mFootZ = inZ;
    // The whole span: nothing else is placed under it, so the passage through it stays open
    arch.mFootRadius = std::sqrt(cArchOuter * cArchOuter + 0.25f * cArchDepth * cArchDepth);
    ioCandidates.push_back(arch);
}

void WorldGenerator::AddDynamic(TileContext& ioContext, std::vector<BodyCreationSettings>& outDynamic) const
{
    // A stream of its own: the props above are the same with or without dynamic bodies
    Pcg32 random(Hash(ioContext.mRandom.Next(), 0x64796e), 3);
    int remaining = mSettings.mDynamicPerTile;
    outDynamic.reserve(size_t(remaining));
    const std::array<int, 3> crateSizes = {cSize050, cSize050, cSize050};
    const float crateRadius = cCrateHalf * std::sqrt(2.0f);
    std::vector<Candidate> candidates;

    // Bodies start 3 cm above the ground (on a slope, tilted to it) so that they settle within a few frames
    auto emit = [&](const std::array<int, 3>& inSizes, float inX, float inZ, const Yaw& inYaw, int inLevel,
                    ObjectLayer inLayer)
    {
        const float hy = 0.5f * cBoxSizes[inSizes[1]];
        const Vec3 normal = ioContext.Normal(inX, inZ, std::max(0.1f, 0.5f * cBoxSizes[inSizes[0]]));
        // The shortest rotation from +y to the normal
        const Quat tilt = Quat(1.0f + normal.y(), normal.z(), 0.0f, -normal.x()).normalized();
        Candidate candidate;
        candidate.mShape = &GetBox(inSizes[0], inSizes[1], inSizes[2]);
        candidate.mPosition = Vec3(inX, ioContext.Height(inX, inZ), inZ) +
                              normal * (hy + 0.03f + float(inLevel) * (2.0f * hy + 0.005f));
        candidate.mRotation = (tilt * inYaw.mRotation).normalized();
        BodyCreationSettings settings = ioContext.MakeBody(candidate, MotionType::Dynamic, inLayer);
        settings.mDensity = random.Range(300.0f, 800.0f);
        outDynamic.push_back(std::move(settings));
    };
    auto fits = [&](float inX, float inZ, float inRadius, float inGap)
    {
        candidates.clear();
        Candidate candidate;
        candidate.mShape = &GetBox(cSize050, cSize050, cSize050);
        candidate.mFootX = inX;
        candidate.mFootZ = inZ;
        candidate.mFootRadius = inRadius;
        candidates.push_back(candidate);
        return ioContext.Fits(*this, candidates, inGap);
    };

    const int maxTries = 20 * mSettings.mDynamicPerTile + 64;
    int tries = 0;
    // A few stacks of 3 to 5 crates
    for (int stacks = std::min(4, remaining / 20); stacks > 0 && tries < maxTries; ++tries)
    {
        const float x = random.Range(0.0f, ioContext.mSize), z = random.Range(0.0f, ioContext.mSize);
        if (!fits(x, z, crateRadius, cPropGap)) continue;
        const Yaw yaw = RandomYaw(random);
        const int height = std::min(random.Int(3, 5), remaining);
        for (int level = 0; level < height; ++level)
            emit(crateSizes, x, z, yaw, level, Layers::cMoving);
        ioContext.mGrid.Add(x, z, crateRadius);
        remaining -= height;
        --stacks;
    }
    // Single crates (40% of the rest), then debris. Crates need walking room and are placed first, while
    // there is room; any that find none are made up by debris, which fits almost anywhere
    int crates = (2 * remaining + 2) / 5;
    for (; remaining > 0 && tries < maxTries; ++tries)
    {
        const float x = random.Range(0.0f, ioContext.mSize), z = random.Range(0.0f, ioContext.mSize);
        const bool crate = crates > 0 && tries < maxTries / 2;
        const std::array<int, 3> sizes =
            crate ? crateSizes
                  : std::array<int, 3>{random.Int(cSize015, cSize030), random.Int(cSize015, cSize030),
                                       random.Int(cSize015, cSize030)};
        const float hx = 0.5f * cBoxSizes[sizes[0]], hz = 0.5f * cBoxSizes[sizes[2]];
        const float radius = std::sqrt(hx * hx + hz * hz);
        if (!fits(x, z, radius, crate ? cPropGap : cDebrisGap)) continue;
        emit(sizes, x, z, RandomYaw(random), 0, crate ? Layers::cMoving : Layers::cDebris);
        ioContext.mGrid.Add(x, z, radius);
        --remaining;
        crates -= crate ? 1 : 0;
    }
}

} // namespace cairn::demo
