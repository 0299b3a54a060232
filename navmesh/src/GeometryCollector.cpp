#include "cairn/navmesh/GeometryCollector.h"

#include "cairn/physics/body/PublishedPose.h"
#include "cairn/physics/shapes/Shape.h"

#include <algorithm>
#include <chrono>

namespace cairn::navmesh
{
using namespace cairn::physics;

namespace
{
using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point inStart)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - inStart).count();
}

/// Whether inInclusion takes a body as published.
bool Takes(const PublishedPose& inPose, const NavMeshInclusion& inInclusion)
{
    switch (inPose.mMotionType)
    {
    case MotionType::Static:
        return true;
    case MotionType::Kinematic:
        return inInclusion.mKinematic;
    case MotionType::Dynamic:
        return inPose.mActive ? inInclusion.mAwakeDynamic : inInclusion.mSleepingDynamic;
    }
    return false;
}
} // namespace

void GeometryCollector::FindBodies(const AABB& inBox, const NavMeshInclusion& inInclusion,
                                   std::vector<BodyID>& outBodies) const
{
    outBodies.clear();
    BroadPhaseQueryFilter filter;
    filter.mObjectLayers = inInclusion.mObjectLayers;
    mBroadPhase.CollideAABox(inBox, filter, [&](BodyID inBody) { outBodies.push_back(inBody); });
    std::sort(outBodies.begin(), outBodies.end());
}

void GeometryCollector::CollectTriangles(const AABB& inBox, const NavMeshInclusion& inInclusion,
                                         std::span<const BodyID> inBodies, TileGeometry& ioGeometry,
                                         CollectStats& ioStats) const
{
    const Clock::time_point start = Clock::now();
    const PoseReader poses(mBodies); // The shapes read stay alive until the collection ends
    thread_local std::vector<Vec3> triangles;
    for (const BodyID& id : inBodies)
    {
        PublishedPose pose;
        if (!poses.Read(id, pose) || !Takes(pose, inInclusion)) continue;
        triangles.clear();
        pose.mShape->CollectTriangles(inBox, pose.mTransform, triangles);
        const uint8_t area = std::min<uint8_t>(pose.mNavMeshArea, cMaxAreaId);
        for (size_t i = 0; i + 2 < triangles.size(); i += 3)
            ioGeometry.AddTriangle(triangles[i], triangles[i + 1], triangles[i + 2], area);
        ioStats.mTriangles += uint32_t(triangles.size() / 3);
        ++ioStats.mBodies;
    }
    ioStats.mCollectMs += MillisecondsSince(start);
}

} // namespace cairn::navmesh
