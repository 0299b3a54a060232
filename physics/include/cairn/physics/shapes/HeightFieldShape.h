#pragma once

// A height field (terrain): a grid of mSampleCountX x mSampleCountZ heights with spacing mCellSize, whose
// sample (x, z) sits at local (x * cellSize, height, z * cellSize). A NaN height, or cHole, makes every cell
// touching that sample a hole (no triangles). Each cell is two triangles; internal edges are flagged as in
// TriangleMeshShape (worked out once, at creation). No volume: static or kinematic bodies only. Immutable:
// safe to share between threads.

#include "cairn/physics/math/Result.h"
#include "cairn/physics/shapes/Shape.h"

#include <span>

namespace cairn::physics
{

class HeightFieldShape final : public Shape
{
public:
    /// Marks a hole sample.
    static constexpr float cHole = std::numeric_limits<float>::quiet_NaN();
    /// Cells at most: two triangles each, whose sub-shape ids (2 per cell) must fit 32 bits.
    static constexpr uint64_t cMaxCells = uint64_t(1) << 31;

    /// inHeights is row-major: index x + z * inSampleCountX. Fails for fewer than 2 x 2 samples, more than
    /// cMaxCells cells, a size mismatch, a cell size that is not finite and > 0, infinite heights, or all
    /// samples holes. Works out every cell's edge flags (about 85 ns a cell: 0.35 ms for 64 x 64 cells).
    static Result<std::shared_ptr<const HeightFieldShape>> Create(uint32_t inSampleCountX,
                                                                  uint32_t inSampleCountZ, float inCellSize,
                                                                  std::span<const float> inHeights);

    uint32_t GetSampleCountX() const { return mSampleCountX; }
    uint32_t GetSampleCountZ() const { return mSampleCountZ; }
    float GetCellSize() const { return mCellSize; }
    /// Height of sample (x, z); NaN for a hole, and for a sample outside the grid (never a read past it).
    float GetHeight(uint32_t inX, uint32_t inZ) const
    {
        if (inX >= mSampleCountX || inZ >= mSampleCountZ) return cHole;
        return mHeights[inX + size_t(inZ) * mSampleCountX];
    }
    /// Active-edge bits of cell (x, z) (x < GetSampleCountX() - 1, z < GetSampleCountZ() - 1): bits 0-2 are
    /// those of its half 0, bits 3-5 of its half 1 (Triangle::mActiveEdges); 0 for a hole, and for a cell
    /// outside the grid.
    uint8_t GetCellActiveEdges(uint32_t inX, uint32_t inZ) const
    {
        if (uint64_t(inX) + 1 >= mSampleCountX || uint64_t(inZ) + 1 >= mSampleCountZ) return 0;
        return mCellActiveEdges[inX + size_t(inZ) * (mSampleCountX - 1)];
    }

    AABB GetLocalBounds() const override;
    MassProperties GetMassProperties(float inDensity) const override; ///< Zero mass: no volume
    void VisitTriangles(const AABB& inLocalBox, TriangleVisitor inVisitor) const override;

    HeightFieldShape(uint32_t inSampleCountX, uint32_t inSampleCountZ, float inCellSize,
                     std::vector<float> inHeights); ///< Use Create()

private:
    bool CastCheckedRay(const RayCast& inLocalRay, RayHit& ioHit) const override; ///< Two-sided

    uint32_t mSampleCountX;
    uint32_t mSampleCountZ;
    float mCellSize;
    std::vector<float> mHeights; ///< Row-major, NaN = hole
    /// Per cell, row-major: computed once at creation (from the cell's neighbours), where working them out on
    /// every visit took a quarter of the time of a query on terrain
    std::vector<uint8_t> mCellActiveEdges;
    AABB mBounds;
};

} // namespace cairn::physics
