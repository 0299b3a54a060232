#include "DetourSurface.h"

#include "DetourPaths.h"

#include <DetourCommon.h>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <unordered_set>

namespace cairn::navmesh
{
namespace
{

Vec3 AcrossXZ(const Vec3& inV)
{
    return Vec3(inV.x(), 0.0f, inV.z());
}

/// The level normal of a polygon's edge from inA to inB (in the polygon's order), into the polygon: Detour's
/// polygons all wind one way (its raycast takes the same side for its normal).
Vec3 InwardNormal(const float* inA, const float* inB)
{
    const Vec3 normal(inB[2] - inA[2], 0.0f, inA[0] - inB[0]);
    const float length = normal.norm();
    return length > 0.0f ? Vec3(normal / length) : Vec3::Zero();
}

/// Nearer a wall than this, the way from the wall to the point gives no normal: the edge's own is taken.
constexpr float cOnWall = 1.0e-4f;

/// The navmesh point of inPolygon nearest inPoint: at the detail mesh's height.
Vec3 OnPolygon(const dtNavMeshQuery& inQuery, dtPolyRef inPolygon, const Vec3& inPoint)
{
    Vec3 onPolygon = inPoint;
    inQuery.closestPointOnPoly(inPolygon, inPoint.data(), onPolygon.data(), nullptr);
    return onPolygon;
}

/// Where a line leaves a polygon it crosses: the fraction along it, and the edge's normal into the polygon.
struct Leaving
{
    float mFraction;
    Vec3 mNormal;
};

std::optional<Leaving> LeavePolygon(const dtNavMesh& inNavMesh, dtPolyRef inPolygon, const Vec3& inFrom,
                                    const Vec3& inTo)
{
    const dtMeshTile* tile = nullptr;
    const dtPoly* polygon = nullptr;
    inNavMesh.getTileAndPolyByRefUnsafe(inPolygon, &tile, &polygon);
    float vertices[DT_VERTS_PER_POLYGON * 3];
    for (int i = 0; i < int(polygon->vertCount); ++i)
        dtVcopy(&vertices[3 * i], &tile->verts[3 * polygon->verts[i]]);
    float enter = 0.0f, leave = 0.0f;
    int enterEdge = -1, leaveEdge = -1;
    if (!dtIntersectSegmentPoly2D(inFrom.data(), inTo.data(), vertices, int(polygon->vertCount), enter, leave,
                                  enterEdge, leaveEdge) ||
        leaveEdge < 0)
        return std::nullopt;
    const int nextEdge = (leaveEdge + 1) % int(polygon->vertCount);
    return Leaving{std::clamp(leave, 0.0f, 1.0f),
                   InwardNormal(&vertices[3 * leaveEdge], &vertices[3 * nextEdge])};
}

/// The highest step of the agent a polygon's navmesh was built for: how far up or down a walk goes on.
float ClimbOf(const dtNavMesh& inNavMesh, dtPolyRef inPolygon)
{
    const dtMeshTile* tile = nullptr;
    const dtPoly* polygon = nullptr;
    inNavMesh.getTileAndPolyByRefUnsafe(inPolygon, &tile, &polygon);
    return std::max(tile->header->walkableClimb, 0.01f);
}

/// How often a walk goes on past a border Detour lost its way at (more than the tile corners a line within
/// the length limit meets), and how far past it it looks for the polygon to go on in (far less than a
/// polygon is wide, far more than a coordinate's rounding).
constexpr int cMaxBorderRetries = 16;
constexpr float cBorderStep = 0.01f;
/// How near a polygon, across x and z, the probe past such a border must be to go on in it.
constexpr float cOnPolygon = 1.0e-3f;

/// The largest number of segments getPolyWallSegments gives for one polygon: each edge splits into portals
/// to the polygons of a neighbouring tile, with walls between them.
constexpr int cMaxPolygonWallSegments = DT_VERTS_PER_POLYGON * 32;

/// The first radius FindWallAround searches: most agents ask near a wall, and a small circle visits few
/// polygons.
constexpr float cFirstWallRadius = 2.0f;

} // namespace

Result<NavRaycastHit> CastAcrossSurface(const dtNavMeshQuery& inQuery, const dtNavMesh& inNavMesh,
                                        dtPolyRef inStart, const Vec3& inStartPoint, const Vec3& inEnd,
                                        const dtQueryFilter& inDetourFilter, const PathFilter& inFilter)
{
    const Vec3 along = AcrossXZ(inEnd - inStartPoint);
    NavRaycastHit result;
    // The walk stops leaving the last polygon it may use (inLeaving: where the line leaves it), at its
    // fraction of the whole line
    auto stopAt = [&](dtPolyRef inLast, const std::optional<Leaving>& inLeaving) -> Result<NavRaycastHit>
    {
        if (!inLeaving)
            return MakeError(ErrorCode::InvalidArgument,
                             "raycast: the line lost its way along Detour's polygons");
        result.mHit = true;
        result.mFraction = inLeaving->mFraction;
        result.mWallNormal = inLeaving->mNormal;
        result.mPosition = OnPolygon(inQuery, inLast, inStartPoint + result.mFraction * along);
        return result;
    };
    auto stopLeaving = [&](dtPolyRef inLast)
    { return stopAt(inLast, LeavePolygon(inNavMesh, inLast, inStartPoint, inEnd)); };
    dtPolyRef from = inStart, last = inStart;
    Vec3 fromPoint = inStartPoint;
    for (int leg = 0;; ++leg)
    {
        dtPolyRef visited[cMaxPathPolygons];
        dtRaycastHit hit{};
        hit.path = visited;
        hit.maxPath = cMaxPathPolygons;
        const dtStatus status =
            inQuery.raycast(from, fromPoint.data(), inEnd.data(), &inDetourFilter, 0, &hit, 0);
        if (dtStatusFailed(status))
            return MakeError(ErrorCode::InvalidArgument, "raycast: Detour refused the line");
        if (dtStatusDetail(status, DT_BUFFER_TOO_SMALL))
            return MakeError(ErrorCode::OutOfCapacity, "raycast: the line crosses more than " +
                                                           std::to_string(cMaxPathPolygons) + " polygons");
        if (hit.pathCount == 0)
        {
            if (leg > 0) return stopLeaving(last);
            // The start is on its polygon's outline and the line leaves it at once
            result.mHit = true;
            result.mFraction = 0.0f;
            result.mPosition = inStartPoint;
            result.mWallNormal = along.norm() > 0.0f ? Vec3(-along.normalized()) : Vec3::Zero();
            return result;
        }
        // Detour crosses into any walkable polygon: the line stops where it would first enter an excluded one
        const int firstExcluded = int(std::find_if(visited, visited + hit.pathCount,
                                                   [&](dtPolyRef inPolygon)
                                                   { return IsExcluded(inNavMesh, inPolygon, inFilter); }) -
                                      visited);
        if (firstExcluded < hit.pathCount)
            return stopLeaving(firstExcluded > 0 ? visited[firstExcluded - 1] : last);
        last = visited[hit.pathCount - 1];
        if (hit.t > 1.0f) break; // Detour's FLT_MAX: the end is in its last polygon
        // Detour stops at a wall with its normal, and with none where it found the polygon across a border
        // but not the line in it: along a tile's border, through a tile's corner, or between tiles built from
        // two moments of a changing world. There the walk goes on from the polygon just past the border, if
        // any
        const bool lostItsWay = hit.hitNormal[0] == 0.0f && hit.hitNormal[2] == 0.0f;
        if (!lostItsWay || leg == cMaxBorderRetries) return stopLeaving(last);
        const std::optional<Leaving> leaving = LeavePolygon(inNavMesh, last, inStartPoint, inEnd);
        if (!leaving) return stopAt(last, leaving);
        const float length = along.norm();
        Vec3 probe = inStartPoint + std::min(leaving->mFraction + cBorderStep / length, 1.0f) * along;
        probe.y() = OnPolygon(inQuery, last, probe).y();
        dtPolyRef next = 0;
        Vec3 onNext;
        const Vec3 extent(cBorderStep, ClimbOf(inNavMesh, last), cBorderStep);
        inQuery.findNearestPoly(probe.data(), extent.data(), &inDetourFilter, &next, onNext.data());
        // The probe may lie on the next polygon's edge (a line along a border): on it counts as in it
        if (next == 0 || next == last || AcrossXZ(onNext - probe).norm() > cOnPolygon)
            return stopAt(last, leaving); // A gap: the border is a wall
        from = next;
        fromPoint = onNext;
    }
    result.mPosition = OnPolygon(inQuery, last, inEnd);
    return result;
}

Result<NavWall> FindWallAround(dtNavMeshQuery& inQuery, const dtNavMesh& inNavMesh, dtPolyRef inStart,
                               const Vec3& inPoint, float inMaxRadius, const dtQueryFilter& inDetourFilter,
                               const PathFilter& inFilter)
{
    // Kept per thread: a query's buffers are larger than its usual answer
    thread_local std::vector<dtPolyRef> polygons(cMaxQueryNodes), parents(cMaxQueryNodes);
    thread_local std::unordered_set<dtPolyRef> outOfReach;
    float segments[cMaxPolygonWallSegments * 6];
    dtPolyRef neighbours[cMaxPolygonWallSegments];
    // A small circle first, then twice as wide up to the radius asked for: the wall nearest the point lies in
    // the first circle that holds a wall
    for (float radius = std::min(inMaxRadius, cFirstWallRadius);;
         radius = std::min(2.0f * radius, inMaxRadius))
    {
        int count = 0;
        const dtStatus status =
            inQuery.findPolysAroundCircle(inStart, inPoint.data(), radius, &inDetourFilter, polygons.data(),
                                          parents.data(), nullptr, &count, cMaxQueryNodes);
        if (dtStatusFailed(status))
            return MakeError(ErrorCode::InvalidArgument, "nearest wall: Detour refused the search");
        if (dtStatusDetail(status, DT_BUFFER_TOO_SMALL) || dtStatusDetail(status, DT_OUT_OF_NODES))
            return MakeError(ErrorCode::OutOfCapacity, "nearest wall: the circle holds more than " +
                                                           std::to_string(cMaxQueryNodes) + " polygons");
        // The nearest wall segment so far: its polygon, the segment's ends and the point on it
        float nearestSquared = radius * radius;
        int nearestPolygon = -1;
        Vec3 nearestA, nearestB, onWall;
        outOfReach.clear();
        // Detour lists a polygon after the one it came from, and an excluded area's high cost makes it come
        // from one outside excluded areas wherever it can: a polygon is out of reach when it is a jump, is
        // excluded, or came from one out of reach
        for (int i = 0; i < count; ++i)
        {
            if (IsOffMeshLink(inNavMesh, polygons[size_t(i)]) ||
                IsExcluded(inNavMesh, polygons[size_t(i)], inFilter) ||
                (!outOfReach.empty() && outOfReach.contains(parents[size_t(i)])))
            {
                outOfReach.insert(polygons[size_t(i)]);
                continue;
            }
            int numSegments = 0;
            if (dtStatusFailed(inQuery.getPolyWallSegments(polygons[size_t(i)], &inDetourFilter, segments,
                                                           neighbours, &numSegments,
                                                           cMaxPolygonWallSegments)))
                return MakeError(ErrorCode::InvalidArgument,
                                 "nearest wall: Detour refused a polygon's edges");
            for (int s = 0; s < numSegments; ++s)
            {
                const dtPolyRef beyond = neighbours[s];
                if (beyond != 0 && !IsExcluded(inNavMesh, beyond, inFilter)) continue; // A way on, not a wall
                const float* a = &segments[6 * s];
                const float* b = a + 3;
                float along = 0.0f;
                const float distanceSquared = dtDistancePtSegSqr2D(inPoint.data(), a, b, along);
                if (distanceSquared > nearestSquared ||
                    (nearestPolygon >= 0 && distanceSquared == nearestSquared))
                    continue;
                nearestSquared = distanceSquared;
                nearestPolygon = i;
                nearestA = Vec3(a[0], a[1], a[2]);
                nearestB = Vec3(b[0], b[1], b[2]);
                dtVlerp(onWall.data(), a, b, along);
            }
        }
        if (nearestPolygon >= 0)
        {
            NavWall nearest;
            nearest.mFound = true;
            nearest.mDistance = std::sqrt(nearestSquared);
            nearest.mPosition = OnPolygon(inQuery, polygons[size_t(nearestPolygon)], onWall);
            const Vec3 away = AcrossXZ(inPoint - onWall);
            nearest.mNormal = away.norm() > cOnWall ? Vec3(away.normalized())
                                                    : InwardNormal(nearestA.data(), nearestB.data());
            return nearest;
        }
        if (radius >= inMaxRadius) return NavWall{};
    }
}

} // namespace cairn::navmesh
