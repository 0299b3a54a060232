#include "LevelSource.h"

#include "cairn/physics/shapes/TriangleMeshShape.h"

#include <algorithm>
#include <cmath>

namespace cairn::bake
{

Result<std::unique_ptr<FileLevelSource>> FileLevelSource::Load(const std::vector<std::string>& inPaths,
                                                               const navmesh::AreaMapping& inAreas,
                                                               float inCellSize)
{
    if (Status valid = inAreas.Validate(); !valid) return valid.GetError();
    if (!(inCellSize > 0.0f) || !std::isfinite(inCellSize))
        return MakeError(ErrorCode::InvalidArgument, "level source: the cell size must be positive");
    std::unique_ptr<FileLevelSource> source(new FileLevelSource());
    source->mPaths = inPaths;
    source->mCellSize = inCellSize;
    for (const std::string& path : inPaths)
    {
        Result<navmesh::IndexedMesh> mesh = navmesh::LoadLevelMesh(path);
        if (!mesh) return mesh.GetError();
        source->mBounds.Encapsulate(mesh.Value().GetBounds());
        for (navmesh::LevelPart& part : navmesh::SplitIntoParts(mesh.Value(), inAreas))
        {
            std::string where = path + (part.mName.empty() ? "" : ": object '" + part.mName + "'");
            auto shape = TriangleMeshShape::Create(part.mMesh.mVertices, part.mMesh.mTriangles);
            if (!shape) return MakeError(shape.GetError().mCode, where + ": " + shape.GetError().mMessage);
            const AABB bounds = part.mMesh.GetBounds();
            source->mParts.push_back({std::move(where), {shape.Value(), part.mArea}, bounds});
        }
    }
    // Each part in every cell its bounds touch (x and z only: levels are wide, not tall)
    for (uint32_t p = 0; p < source->mParts.size(); ++p)
    {
        const AABB& bounds = source->mParts[p].mBounds;
        const int32_t x0 = int32_t(std::floor(bounds.mMin.x() / inCellSize)),
                      x1 = int32_t(std::floor(bounds.mMax.x() / inCellSize)),
                      z0 = int32_t(std::floor(bounds.mMin.z() / inCellSize)),
                      z1 = int32_t(std::floor(bounds.mMax.z() / inCellSize));
        for (int32_t x = x0; x <= x1; ++x)
            for (int32_t z = z0; z <= z1; ++z)
                source->mCells[source->CellKey(x, z)].push_back(p);
    }
    source->mSeen.assign(source->mParts.size(), 0);
    return source;
}

void FileLevelSource::FindObjects(const AABB& inBox, std::vector<SourceObject>& ioObjects) const
{
    // A part in several cells is reported once: stamped per call
    if (++mStamp == 0)
    {
        std::fill(mSeen.begin(), mSeen.end(), 0);
        mStamp = 1;
    }
    const int32_t x0 = int32_t(std::floor(inBox.mMin.x() / mCellSize)),
                  x1 = int32_t(std::floor(inBox.mMax.x() / mCellSize)),
                  z0 = int32_t(std::floor(inBox.mMin.z() / mCellSize)),
                  z1 = int32_t(std::floor(inBox.mMax.z() / mCellSize));
    for (int32_t x = x0; x <= x1; ++x)
        for (int32_t z = z0; z <= z1; ++z)
        {
            auto cell = mCells.find(CellKey(x, z));
            if (cell == mCells.end()) continue;
            for (uint32_t p : cell->second)
            {
                if (mSeen[p] == mStamp) continue;
                mSeen[p] = mStamp;
                if (mParts[p].mBounds.Overlaps(inBox)) ioObjects.push_back({p, mParts[p].mBounds});
            }
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
