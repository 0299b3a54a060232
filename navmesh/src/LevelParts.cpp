// Splitting a level file into static bodies: one per object and area (see SplitIntoParts in LevelMesh.h).

#include "cairn/navmesh/LevelMesh.h"

#include <algorithm>
#include <string>
#include <unordered_map>

namespace cairn::navmesh
{
using namespace cairn::physics;

Status IndexedMesh::Validate() const
{
    for (size_t t = 0; t < mTriangles.size(); ++t)
        for (const uint32_t vertex : mTriangles[t])
            if (vertex >= mVertices.size())
                return MakeError(ErrorCode::InvalidArgument, "level mesh: triangle " + std::to_string(t) +
                                                                 " uses vertex " + std::to_string(vertex) +
                                                                 " of " + std::to_string(mVertices.size()));
    for (const MeshObject& object : mObjects)
        // In 64 bits: a first triangle and a count near 2^32 must not wrap into range
        if (uint64_t(object.mFirstTriangle) + object.mNumTriangles > mTriangles.size())
            return MakeError(ErrorCode::InvalidArgument,
                             "level mesh: object '" + object.mName + "' has triangles " +
                                 std::to_string(object.mFirstTriangle) + " to " +
                                 std::to_string(uint64_t(object.mFirstTriangle) + object.mNumTriangles) +
                                 " of " + std::to_string(mTriangles.size()));
    return Status::Ok();
}

Result<IndexedMesh> IndexedMesh::ExtractTriangles(std::span<const uint32_t> inTriangles) const
{
    IndexedMesh part;
    std::unordered_map<uint32_t, uint32_t> newIndex; // Old vertex index -> index in the part
    part.mTriangles.reserve(std::min(inTriangles.size(), mTriangles.size()));
    for (uint32_t t : inTriangles)
    {
        if (t >= mTriangles.size())
            return MakeError(ErrorCode::InvalidArgument, "level mesh: triangle " + std::to_string(t) +
                                                             " of " + std::to_string(mTriangles.size()));
        std::array<uint32_t, 3> triangle;
        for (size_t k = 0; k < 3; ++k)
        {
            const uint32_t old = mTriangles[t][k];
            if (old >= mVertices.size())
                return MakeError(ErrorCode::InvalidArgument, "level mesh: triangle " + std::to_string(t) +
                                                                 " uses vertex " + std::to_string(old) +
                                                                 " of " + std::to_string(mVertices.size()));
            auto [it, inserted] = newIndex.try_emplace(old, uint32_t(part.mVertices.size()));
            if (inserted) part.mVertices.push_back(mVertices[old]);
            triangle[k] = it->second;
        }
        part.mTriangles.push_back(triangle);
    }
    return part;
}

const std::string& IndexedMesh::GetMaterialName(uint32_t inTriangle) const
{
    static const std::string none;
    if (inTriangle >= mTriangleMaterials.size()) return none;
    const uint32_t material = mTriangleMaterials[inTriangle];
    return material < mMaterials.size() ? mMaterials[material] : none;
}

uint8_t AreaMapping::GetArea(const std::string& inMaterial) const
{
    auto it = mMaterialAreas.find(inMaterial);
    return it != mMaterialAreas.end() ? it->second : mDefaultArea;
}

Status AreaMapping::Validate() const
{
    if (mDefaultArea > cMaxAreaId)
        return MakeError(ErrorCode::InvalidArgument,
                         "the default area id is above " + std::to_string(cMaxAreaId));
    for (const auto& [material, area] : mMaterialAreas)
        if (area > cMaxAreaId)
            return MakeError(ErrorCode::InvalidArgument, "material '" + material + "': area id " +
                                                             std::to_string(area) + " is above " +
                                                             std::to_string(cMaxAreaId));
    return Status::Ok();
}

Result<std::vector<LevelPart>> SplitIntoParts(const IndexedMesh& inMesh, const AreaMapping& inAreas)
{
    if (Status valid = inMesh.Validate(); !valid) return valid.GetError();
    std::vector<MeshObject> objects = inMesh.mObjects;
    if (objects.empty()) objects.push_back({"", 0, uint32_t(inMesh.mTriangles.size())});
    std::vector<LevelPart> parts;
    std::vector<uint8_t> areas;                   // Of one object, in order of first use
    std::vector<std::vector<uint32_t>> triangles; // Of each of those areas
    for (const MeshObject& object : objects)
    {
        areas.clear();
        triangles.clear();
        for (uint32_t t = object.mFirstTriangle; t < object.mFirstTriangle + object.mNumTriangles; ++t)
        {
            const uint8_t area = inAreas.GetArea(inMesh.GetMaterialName(t));
            size_t slot = 0;
            while (slot < areas.size() && areas[slot] != area)
                ++slot;
            if (slot == areas.size())
            {
                areas.push_back(area);
                triangles.emplace_back();
            }
            triangles[slot].push_back(t);
        }
        for (size_t a = 0; a < areas.size(); ++a)
            parts.push_back({object.mName, areas[a], inMesh.ExtractTriangles(triangles[a]).Value()}); // Valid
    }
    return parts;
}

} // namespace cairn::navmesh
