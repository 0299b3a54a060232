#include "cairn/navmesh/GeometryCollector.h"

#include "cairn/physics/body/BodyLock.h"

#include <algorithm>
#include <chrono>

namespace cairn::navmesh
{

namespace
{
using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point inStart)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - inStart).count();
}

/// What a body contributes, copied under its lock.
struct BodyCopy
{
    ShapeRef mShape;
    Transform mTransform;
    uint8_t mArea = cDefaultArea;
};

/// Whether inInclusion takes a body that is not static.
bool Takes(const Body& inBody, const NavMeshInclusion& inInclusion)
{
    if (inBody.IsKinematic()) return inInclusion.mKinematic;
    return inBody.IsDynamic() && inInclusion.mSleepingDynamic && !inBody.IsActive();
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
                                         std::vector<BodyID>& outBusy, CollectStats& ioStats,
                                         BodyKinds inKinds) const
{
    const Clock::time_point start = Clock::now();
    thread_local std::vector<Vec3> triangles;
    for (const BodyID& id : inBodies)
    {
        BodyCopy copy;
        bool taken = false;
        {
            double waitMs = 0.0;
            StaticBodyLockRead staticLock(mBodies, id, &waitMs);
            ioStats.mLongestLockWaitMs = std::max(ioStats.mLongestLockWaitMs, waitMs);
            if (const Body* body = staticLock.GetBody();
                body != nullptr && body->IsInWorld() && inKinds != BodyKinds::NonStatic)
            {
                copy = {body->GetShape(), body->GetTransform(), body->GetNavMeshArea()};
                taken = true;
            }
            else if (staticLock.WasNotStatic() && inKinds != BodyKinds::Static)
            {
                // An awake dynamic body is no obstacle: skipped without its body lock, which the step may
                // hold (if it falls asleep after this, the change marks the tile dirty again)
                const MotionType motion = staticLock.GetNotStaticMotionType();
                const bool wanted = motion == MotionType::Kinematic
                                        ? inInclusion.mKinematic
                                        : inInclusion.mSleepingDynamic && !staticLock.WasActive();
                staticLock.Release();
                if (!wanted) continue;
                BodyLockRead lock(mBodies, id, TryLock{});
                if (lock.WasBusy())
                {
                    outBusy.push_back(id);
                    ++ioStats.mBusy;
                    continue;
                }
                if (const Body* body = lock.GetBody();
                    body != nullptr && body->IsInWorld() && Takes(*body, inInclusion))
                {
                    copy = {body->GetShape(), body->GetTransform(), body->GetNavMeshArea()};
                    taken = true;
                }
            }
        }
        // Every lock released: the shape is immutable and the copied reference keeps it alive
        if (!taken || copy.mShape == nullptr) continue;
        triangles.clear();
        copy.mShape->CollectTriangles(inBox, copy.mTransform, triangles);
        const uint8_t area = std::min<uint8_t>(copy.mArea, cMaxAreaId);
        for (size_t i = 0; i + 2 < triangles.size(); i += 3)
            ioGeometry.AddTriangle(triangles[i], triangles[i + 1], triangles[i + 2], area);
        ioStats.mTriangles += uint32_t(triangles.size() / 3);
        ++ioStats.mBodies;
    }
    ioStats.mCollectMs += MillisecondsSince(start);
}

} // namespace cairn::navmesh
