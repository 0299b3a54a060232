#pragma once

// BenchScenes: the physics scenes of ../shared/bench/SPEC.md that more than one benchmark program builds
// (step_pyramid: cairn-bench-step times its step, cairn-bench-query-latency queries it while it steps), made
// in one place so that every program measures the same bodies, added in the same order (the step's result,
// and so cairn-bench-step's checksum, depends on the order of the body ids). Main thread, before the world
// steps.

#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/BoxShape.h"

#include <vector>

namespace cairn::tools
{
using namespace cairn::physics;

/// A box body as the shared workload describes them: density 1000, no restitution, turned inYaw about +Y;
/// static boxes in the static layer, the others in the moving one.
inline BodyCreationSettings BoxSettings(const Vec3& inCenter, const Vec3& inHalfExtent, float inYaw,
                                        MotionType inMotion, float inFriction)
{
    BodyCreationSettings settings;
    settings.mShape = BoxShape::Create(inHalfExtent).Value();
    settings.mPosition = inCenter;
    settings.mRotation = Quat(Eigen::AngleAxisf(inYaw, Vec3::UnitY()));
    settings.mMotionType = inMotion;
    settings.mObjectLayer = inMotion == MotionType::Static ? Layers::cStatic : Layers::cMoving;
    settings.mFriction = inFriction;
    settings.mRestitution = 0.0f;
    settings.mDensity = 1000.0f;
    return settings;
}

/// Adds bodies in one batch, as a streaming loader would; appends their ids to outIDs in the order of
/// inSettings.
inline void AddBatch(BodyInterface& ioBodies, const std::vector<BodyCreationSettings>& inSettings,
                     Activation inActivation, std::vector<BodyID>& outIDs)
{
    std::vector<BodyID> ids;
    for (const BodyCreationSettings& settings : inSettings)
        ids.push_back(ioBodies.CreateBody(settings).Value());
    BodyInterface::AddBatch batch = ioBodies.AddBodiesPrepare(ids).Value();
    (void)ioBodies.AddBodiesFinalize(batch, inActivation);
    outIDs.insert(outIDs.end(), ids.begin(), ids.end());
}

/// The step benchmarks' world settings: SPEC.md's 10 velocity and 2 position iterations, room for the
/// shared world's 22,020 bodies; inCandidateMargin is the broad phase's static candidate margin (the
/// engine's default unless a program is told otherwise).
inline PhysicsSettings BenchSettings(bool inAllowSleeping,
                                     float inCandidateMargin = PhysicsSettings().mBroadPhaseCandidateMargin)
{
    PhysicsSettings settings;
    settings.mMaxBodies = 32768;
    settings.mSolver.mVelocityIterations = 10;
    settings.mSolver.mPositionIterations = 2;
    settings.mAllowSleeping = inAllowSleeping;
    settings.mBroadPhaseCandidateMargin = inCandidateMargin;
    return settings;
}

/// step_pyramid: SPEC.md's layout, stepped at 1/60 s with one collision step and sleeping disabled (so every
/// box stays awake and in the step for the whole run).
inline constexpr float cPyramidStepSeconds = 1.0f / 60.0f;
inline constexpr bool cPyramidAllowSleeping = false;
inline constexpr int cPyramidLayers = 15;
/// The boxes' footprint as built (x and z in [-16, 14]; the pyramid settles within it, give or take a few
/// centimetres) and the floor's top (y = 0; the floor reaches to x, z = +-50).
inline constexpr float cPyramidFootprintMin = -16.0f;
inline constexpr float cPyramidFootprintMax = 14.0f;
inline constexpr float cPyramidFloorHalfExtent = 50.0f;
/// The top of the highest box as built (layer 14 at y = 36, half extent 1); it sinks as the layers settle.
inline constexpr float cPyramidTop = 37.0f;

/// The boxes of step_pyramid, in SPEC.md's order (layer, then j, then k): 1,240 dynamic 2 m boxes.
inline std::vector<BodyCreationSettings> PyramidBoxSettings()
{
    std::vector<BodyCreationSettings> boxes;
    for (int i = 0; i < cPyramidLayers; ++i)
        for (int j = i / 2; j < cPyramidLayers - (i + 1) / 2; ++j)
            for (int k = i / 2; k < cPyramidLayers - (i + 1) / 2; ++k)
            {
                const float offset = (i % 2 == 1) ? 1.0f : 0.0f;
                boxes.push_back(BoxSettings(Vec3(-15.0f + 2.0f * float(j) + offset, 1.0f + 2.5f * float(i),
                                                 -15.0f + 2.0f * float(k) + offset),
                                            Vec3(1, 1, 1), 0, MotionType::Dynamic, 0.2f));
            }
    return boxes;
}

struct PyramidScene
{
    std::vector<BodyID> mFloor; ///< The one static floor box
    std::vector<BodyID> mBoxes; ///< The pyramid's boxes, awake
};

/// Adds step_pyramid's floor (one batch, not activated) then its boxes (one batch, activated) to an empty
/// world made with BenchSettings(cPyramidAllowSleeping).
inline PyramidScene AddPyramid(BodyInterface& ioBodies)
{
    PyramidScene scene;
    AddBatch(ioBodies,
             {BoxSettings(Vec3(0, -1, 0), Vec3(cPyramidFloorHalfExtent, 1, cPyramidFloorHalfExtent), 0,
                          MotionType::Static, 0.2f)},
             Activation::DontActivate, scene.mFloor);
    AddBatch(ioBodies, PyramidBoxSettings(), Activation::Activate, scene.mBoxes);
    return scene;
}

} // namespace cairn::tools
