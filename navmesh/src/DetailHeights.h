#pragma once

// DetailHeights: how far each polygon's detail surface strays from the voxels it was sampled from, and a
// detail mesh that takes each polygon's triangles from whichever of two builds strays least.
//
// Why: Recast samples a polygon's inner heights on a grid of the detail sample distance and keeps those
// samples half that distance away from the polygon's edges. Steps climbed inside one polygon (a crate on a
// platform on a slope, each step under the agent's climb) are smeared into a ramp across that band, and an
// agent takes its height from the ramp. In the demo's world a ramp ran 1.2 m under the top of a crate that
// agents walk over, and an agent crossing it had its chest inside the crate. Detour's crowd and Recast's
// sample have the same surface; the measure lets the tile builder find such polygons and sample them again
// finely, and tells how far off the surface still is.
//
// Plain functions on one build's Recast data (one thread).

#include <span>
#include <vector>

struct rcCompactHeightfield;
struct rcPolyMesh;
struct rcPolyMeshDetail;

namespace cairn::navmesh
{

/// A detail mesh in Recast's layout (rcPolyMeshDetail's arrays), owned.
struct DetailMeshArrays
{
    std::vector<unsigned int> mMeshes; ///< Per polygon: first vertex, vertices, first triangle, triangles
    std::vector<float> mVerts;
    std::vector<unsigned char> mTris; ///< Per triangle: three local vertex indices and edge flags
};

/// For each polygon of inMesh: the largest vertical distance (m) between its detail surface in inDetail and
/// the walkable surface of its region in inCompact, over the cells whose centres the polygon covers. A cell
/// where the region has no span (eroded, or another region's) is not measured, so a polygon made of several
/// regions measures 0.
std::vector<float> MeasureDetailErrors(const rcPolyMesh& inMesh, const rcPolyMeshDetail& inDetail,
                                       const rcCompactHeightfield& inCompact);

/// A polygon mesh of inMesh's polygons listed in inPolygons (in that order, their neighbour links dropped)
/// and all its vertices, in Recast's memory (rcFreePolyMesh frees it): Recast's detail builder then samples
/// just those polygons. Null when Recast's allocator fails.
rcPolyMesh* CopyPolygons(const rcPolyMesh& inMesh, std::span<const int> inPolygons);

/// Polygon p's vertices and triangles from inFine where p is inFinePolygons[k] and inFineErrors[k] is below
/// ioErrors[p] (then ioErrors[p] becomes inFineErrors[k]), else from inCoarse. inCoarse is the detail mesh of
/// every polygon and ioErrors its errors, inFine that of the polygons in inFinePolygons (ascending), in that
/// order. outNumFromFine: the polygons taken from inFine.
DetailMeshArrays MergeDetailMeshes(const rcPolyMeshDetail& inCoarse, std::vector<float>& ioErrors,
                                   const rcPolyMeshDetail& inFine, const std::vector<float>& inFineErrors,
                                   std::span<const int> inFinePolygons, int& outNumFromFine);

} // namespace cairn::navmesh
