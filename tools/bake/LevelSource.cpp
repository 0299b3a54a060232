#include "LevelSource.h"

#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <algorithm>
#include <cmath>

namespace cairn::bake
{
using namespace cairn::physics;

Result<std::unique_ptr<FileLevelSource>> FileLevelSource::Load(const std::vector<std::string>& inPaths,
                                                               const navmesh::AreaMapping& inAreas,
                                                               float inCellSize,
                                                               const navmesh::LevelLoadLimits& inLimits)
{
    if (Status valid = inAreas.Validate(); !valid) return valid.GetError();
    if (!(inCellSize > 0.0f) || !std::isfinite(inCellSize))
        return MakeError(ErrorCode::InvalidArgument, "level source: the cell size must be positive");
    std::unique_ptr<FileLevelSource> source(new FileLevelSource());
    source->mPaths = inPaths;
    source->mCellSize = inCellSize;
    for (const std::string& path : inPaths)
    {
        Result<navmesh::IndexedMesh> mesh = navmesh::LoadLevelMesh(path, inLimits);
        if (!mesh) return mesh.GetError();
        source->mBounds.Encapsulate(mesh.Value().GetBounds());
        Result<std::vector<navmesh::LevelPart>> parts = navmesh::SplitIntoParts(mesh.Value(), inAreas);
        if (!parts) return MakeError(parts.GetError().mCode, path + ": " + parts.GetError().mMessage);
        for (navmesh::LevelPart& part : parts.Value())
        {
            std::string where = path + (part.mName.empty() ? "" : ": object '" + part.mName + "'");
            auto shape = TriangleMeshShape::Create(part.mMesh.mVertices, part.mMesh.mTriangles);
            // A part of zero-area triangles only (a collapsed helper object) has no surface to walk on or
            // bump into: left out, as degenerate triangles among good ones are
            if (!shape && shape.GetError().mCode == ErrorCode::DegenerateShape) continue;
            if (!shape) return MakeError(shape.GetError().mCode, where + ": " + shape.GetError().mMessage);
            const AABB bounds = part.mMesh.GetBounds();
            source->mParts.push_back({std::move(where), {shape.Value(), part.mArea}, bounds});
        }
    }
    // Each part in every cell its bounds touch (x and z only: levels are wide, not tall); a part over more
    // cells than that (a terrain, a long road) goes in a list every query looks at instead, so the index
    // stays in proportion to the parts
    for (uint32_t p = 0; p < source->mParts.size(); ++p)
    {
        const CellRange cells = source->CellsOf(source->mParts[p].mBounds);
        if ((cells.mX1 - cells.mX0 + 1) * (cells.mZ1 - cells.mZ0 + 1) > cMaxCellsPerPart)
        {
            source->mLargeParts.push_back(p);
            continue;
        }
        for (int64_t x = cells.mX0; x <= cells.mX1; ++x)
            for (int64_t z = cells.mZ0; z <= cells.mZ1; ++z)
                source->mCells[source->CellKey(x, z)].push_back(p);
    }
    source->mSeen.assign(source->mParts.size(), 0);
    return source;
}

FileLevelSource::CellRange FileLevelSource::CellsOf(const AABB& inBox) const
{
    // In doubles and clamped: coordinates are within the world's range, but divided by a small cell they
    // would overflow 32 bits
    auto cell = [&](float inCoordinate)
    {
        return int64_t(
            std::clamp(std::floor(double(inCoordinate) / mCellSize), -double(1 << 30), double(1 << 30)));
    };
    return {cell(inBox.mMin.x()), cell(inBox.mMax.x()), cell(inBox.mMin.z()), cell(inBox.mMax.z())};
}

void FileLevelSource::FindObjects(const AABB& inBox, std::vector<SourceObject>& ioObjects) const
{
    // A part in several cells is reported once: stamped per call
    if (++mStamp == 0)
    {
        std::fill(mSeen.begin(), mSeen.end(), 0);
        mStamp = 1;
    }
    auto consider = [&](uint32_t inPart)
    {
        if (mSeen[inPart] == mStamp) return;
        mSeen[inPart] = mStamp;
        if (mParts[inPart].mBounds.Overlaps(inBox)) ioObjects.push_back({inPart, mParts[inPart].mBounds});
    };
    for (uint32_t part : mLargeParts)
        consider(part);
    const CellRange cells = CellsOf(inBox);
    if ((cells.mX1 - cells.mX0 + 1) * (cells.mZ1 - cells.mZ0 + 1) > int64_t(mCells.size()))
    {
        // A box over more cells than are filled: look at the filled ones
        for (const auto& [key, parts] : mCells)
            for (uint32_t part : parts)
                consider(part);
        return;
    }
    for (int64_t x = cells.mX0; x <= cells.mX1; ++x)
        for (int64_t z = cells.mZ0; z <= cells.mZ1; ++z)
        {
            auto cell = mCells.find(CellKey(x, z));
            if (cell == mCells.end()) continue;
            for (uint32_t part : cell->second)
                consider(part);
        }
}

Result<SourceBody> FileLevelSource::MakeBody(uint64_t inKey) const
{
    if (inKey >= mParts.size())
        return MakeError(ErrorCode::InvalidArgument, "level source: no object " + std::to_string(inKey));
    return mParts[inKey].mBody;
}

std::string FileLevelSource::Describe(uint64_t inKey) const
{
    return inKey < mParts.size() ? mParts[inKey].mWhere : "object " + std::to_string(inKey) + " (unknown)";
}

} // namespace cairn::bake
