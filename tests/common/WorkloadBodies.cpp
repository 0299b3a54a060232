#include "common/WorkloadBodies.h"

#include "cairn/physics/shapes/BoxShape.h"

namespace cairn
{
using namespace cairn::physics;

BodyCreationSettings WorkloadBoxSettings(const BenchBox& inBox, MotionType inMotion)
{
    BodyCreationSettings settings;
    settings.mShape = BoxShape::Create(inBox.mHalfExtent).Value();
    settings.mPosition = inBox.mCenter;
    settings.mRotation = Quat(Eigen::AngleAxisf(inBox.mYaw, Vec3::UnitY()));
    settings.mMotionType = inMotion;
    settings.mObjectLayer = inMotion == MotionType::Static ? Layers::cStatic : Layers::cMoving;
    settings.mFriction = 0.5f;
    settings.mRestitution = 0.0f;
    settings.mDensity = 1000.0f;
    return settings;
}

std::vector<BodyID> AddWorkloadBoxes(BodyInterface& ioBodies, const std::vector<BenchBox>& inBoxes,
                                     MotionType inMotion, bool inActivateDynamic)
{
    std::vector<BodyID> ids;
    ids.reserve(inBoxes.size());
    const auto refused = [&]
    {
        for (const BodyID& id : ids)
            (void)ioBodies.DestroyBody(id);
        return std::vector<BodyID>();
    };
    for (const BenchBox& box : inBoxes)
    {
        const Result<BodyID> id = ioBodies.CreateBody(WorkloadBoxSettings(box, inMotion));
        if (!id) return refused();
        ids.push_back(id.Value());
    }
    Result<BodyInterface::AddBatch> batch = ioBodies.AddBodiesPrepare(ids);
    if (!batch) return refused();
    const Activation activation =
        inMotion != MotionType::Static && inActivateDynamic ? Activation::Activate : Activation::DontActivate;
    if (!ioBodies.AddBodiesFinalize(batch.Value(), activation)) return refused();
    return ids;
}

} // namespace cairn
