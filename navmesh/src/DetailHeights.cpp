#include "DetailHeights.h"

#include <Recast.h>
#include <RecastAlloc.h>
#include <algorithm>
#include <cmath>
#include <limits>

namespace cairn::navmesh
{
namespace
{

/// The distance from inHeight to the nearest span of inRegion in cell (inX, inZ) of the polygon mesh, or
/// infinity where the region has none there.
float DistanceToRegion(const rcPolyMesh& inMesh, const rcCompactHeightfield& inCompact,
                       unsigned short inRegion, int inX, int inZ, float inHeight)
{
    // The polygon mesh's cells start after the compact heightfield's border
    const int x = inX + inMesh.borderSize, z = inZ + inMesh.borderSize;
    if (x < 0 || z < 0 || x >= inCompact.width || z >= inCompact.height)
        return std::numeric_limits<float>::infinity();
    const rcCompactCell& cell = inCompact.cells[x + z * inCompact.width];
    float nearest = std::numeric_limits<float>::infinity();
    for (unsigned int s = cell.index; s < cell.index + unsigned(cell.count); ++s)
        if (inCompact.spans[s].reg == inRegion)
            // Recast lifts its detail vertices one cell height above the span's floor; so does this
            nearest = std::min(
                nearest,
                std::abs(inHeight - (inCompact.bmin[1] + float(inCompact.spans[s].y + 1) * inCompact.ch)));
    return nearest;
}

/// The largest distance between polygon inPoly's detail surface and its region's spans, over the cell centres
/// each of its detail triangles covers (a centre on an edge shared by two triangles is measured twice, with
/// the same height).
float MeasurePolygon(const rcPolyMesh& inMesh, const rcPolyMeshDetail& inDetail,
                     const rcCompactHeightfield& inCompact, int inPoly)
{
    const unsigned short region = inMesh.regs[inPoly];
    if (region == RC_MULTIPLE_REGS) return 0.0f;
    const unsigned int* range = &inDetail.meshes[inPoly * 4];
    const float* verts = &inDetail.verts[range[0] * 3];
    const float toCells = 1.0f / inMesh.cs;
    float largest = 0.0f;
    for (unsigned int t = 0; t < range[3]; ++t)
    {
        const unsigned char* tri = &inDetail.tris[(range[2] + t) * 4];
        const float* a = &verts[tri[0] * 3];
        const float* b = &verts[tri[1] * 3];
        const float* c = &verts[tri[2] * 3];
        const float area = (b[0] - a[0]) * (c[2] - a[2]) - (c[0] - a[0]) * (b[2] - a[2]);
        if (std::abs(area) < 1e-12f) continue;
        // The cells whose centres may lie in the triangle, in the polygon mesh's cells
        const int minX = int(std::floor((std::min({a[0], b[0], c[0]}) - inMesh.bmin[0]) * toCells - 0.5f));
        const int maxX = int(std::ceil((std::max({a[0], b[0], c[0]}) - inMesh.bmin[0]) * toCells - 0.5f));
        const int minZ = int(std::floor((std::min({a[2], b[2], c[2]}) - inMesh.bmin[2]) * toCells - 0.5f));
        const int maxZ = int(std::ceil((std::max({a[2], b[2], c[2]}) - inMesh.bmin[2]) * toCells - 0.5f));
        for (int z = minZ; z <= maxZ; ++z)
            for (int x = minX; x <= maxX; ++x)
            {
                const float centreX = inMesh.bmin[0] + (float(x) + 0.5f) * inMesh.cs;
                const float centreZ = inMesh.bmin[2] + (float(z) + 0.5f) * inMesh.cs;
                const float u =
                    ((b[0] - centreX) * (c[2] - centreZ) - (c[0] - centreX) * (b[2] - centreZ)) / area;
                const float v =
                    ((c[0] - centreX) * (a[2] - centreZ) - (a[0] - centreX) * (c[2] - centreZ)) / area;
                const float w = 1.0f - u - v;
                constexpr float cOnEdge = -1e-4f;
                if (u < cOnEdge || v < cOnEdge || w < cOnEdge) continue;
                const float distance =
                    DistanceToRegion(inMesh, inCompact, region, x, z, u * a[1] + v * b[1] + w * c[1]);
                if (std::isfinite(distance)) largest = std::max(largest, distance);
            }
    }
    return largest;
}

} // namespace

std::vector<float> MeasureDetailErrors(const rcPolyMesh& inMesh, const rcPolyMeshDetail& inDetail,
                                       const rcCompactHeightfield& inCompact)
{
    std::vector<float> errors(size_t(inMesh.npolys), 0.0f);
    for (int p = 0; p < inMesh.npolys && p < inDetail.nmeshes; ++p)
        errors[size_t(p)] = MeasurePolygon(inMesh, inDetail, inCompact, p);
    return errors;
}

rcPolyMesh* CopyPolygons(const rcPolyMesh& inMesh, std::span<const int> inPolygons)
{
    rcPolyMesh* copy = rcAllocPolyMesh();
    if (copy == nullptr) return nullptr;
    const size_t numPolygons = inPolygons.size(), polyStride = size_t(inMesh.nvp) * 2;
    copy->verts = static_cast<unsigned short*>(
        rcAlloc(sizeof(unsigned short) * size_t(inMesh.nverts) * 3, RC_ALLOC_PERM));
    copy->polys = static_cast<unsigned short*>(
        rcAlloc(sizeof(unsigned short) * numPolygons * polyStride, RC_ALLOC_PERM));
    copy->regs = static_cast<unsigned short*>(rcAlloc(sizeof(unsigned short) * numPolygons, RC_ALLOC_PERM));
    copy->flags = static_cast<unsigned short*>(rcAlloc(sizeof(unsigned short) * numPolygons, RC_ALLOC_PERM));
    copy->areas = static_cast<unsigned char*>(rcAlloc(numPolygons, RC_ALLOC_PERM));
    if (copy->verts == nullptr || copy->polys == nullptr || copy->regs == nullptr || copy->flags == nullptr ||
        copy->areas == nullptr)
    {
        rcFreePolyMesh(copy);
        return nullptr;
    }
    std::copy_n(inMesh.verts, size_t(inMesh.nverts) * 3, copy->verts);
    for (size_t k = 0; k < numPolygons; ++k)
    {
        const size_t from = size_t(inPolygons[k]);
        std::copy_n(inMesh.polys + from * polyStride, polyStride / 2, copy->polys + k * polyStride);
        // The detail builder reads no neighbours; none is kept, as their indices are the whole mesh's
        std::fill_n(copy->polys + k * polyStride + polyStride / 2, polyStride / 2, RC_MESH_NULL_IDX);
        copy->regs[k] = inMesh.regs[from];
        copy->flags[k] = inMesh.flags[from];
        copy->areas[k] = inMesh.areas[from];
    }
    copy->nverts = inMesh.nverts;
    copy->npolys = copy->maxpolys = int(numPolygons);
    copy->nvp = inMesh.nvp;
    std::copy_n(inMesh.bmin, 3, copy->bmin);
    std::copy_n(inMesh.bmax, 3, copy->bmax);
    copy->cs = inMesh.cs;
    copy->ch = inMesh.ch;
    copy->borderSize = inMesh.borderSize;
    copy->maxEdgeError = inMesh.maxEdgeError;
    return copy;
}

DetailMeshArrays MergeDetailMeshes(const rcPolyMeshDetail& inCoarse, std::vector<float>& ioErrors,
                                   const rcPolyMeshDetail& inFine, const std::vector<float>& inFineErrors,
                                   std::span<const int> inFinePolygons, int& outNumFromFine)
{
    DetailMeshArrays merged;
    outNumFromFine = 0;
    merged.mMeshes.reserve(size_t(inCoarse.nmeshes) * 4);
    size_t nextFine = 0; // inFinePolygons is in polygon order
    for (int p = 0; p < inCoarse.nmeshes; ++p)
    {
        const rcPolyMeshDetail* from = &inCoarse;
        int index = p;
        if (nextFine < inFinePolygons.size() && inFinePolygons[nextFine] == p)
        {
            if (int(nextFine) < inFine.nmeshes && inFineErrors[nextFine] < ioErrors[size_t(p)])
            {
                from = &inFine;
                index = int(nextFine);
                ioErrors[size_t(p)] = inFineErrors[nextFine];
                ++outNumFromFine;
            }
            ++nextFine;
        }
        const unsigned int* range = &from->meshes[index * 4];
        merged.mMeshes.insert(merged.mMeshes.end(), {unsigned(merged.mVerts.size() / 3), range[1],
                                                     unsigned(merged.mTris.size() / 4), range[3]});
        merged.mVerts.insert(merged.mVerts.end(), from->verts + range[0] * 3,
                             from->verts + (range[0] + range[1]) * 3);
        merged.mTris.insert(merged.mTris.end(), from->tris + range[2] * 4,
                            from->tris + (range[2] + range[3]) * 4);
    }
    return merged;
}

} // namespace cairn::navmesh
