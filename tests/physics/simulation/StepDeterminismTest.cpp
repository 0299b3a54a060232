// Determinism of the parallel step: the same scene stepped 600 times gives bit-identical body states run
// after run with the same number of threads, and the same states with no job system and with 1, 2 and 4
// threads (pairs, contacts, waking and islands are made canonical, see PhysicsStep.h).

#include "SimulationFixture.h"
#include "common/StaticFloor.h"

#include <cstring>
#include <vector>

namespace cairn::test
{
namespace
{

struct BodyState
{
    Vec3 mPosition;
    Quat mRotation;
    Vec3 mLinearVelocity;
    Vec3 mAngularVelocity;
    bool mActive;
};

bool BitIdentical(const BodyState& inL, const BodyState& inR)
{
    auto same = [](const auto& inA, const auto& inB) { return std::memcmp(&inA, &inB, sizeof(inA)) == 0; };
    return same(inL.mPosition, inR.mPosition) && same(inL.mRotation.coeffs(), inR.mRotation.coeffs()) &&
           same(inL.mLinearVelocity, inR.mLinearVelocity) &&
           same(inL.mAngularVelocity, inR.mAngularVelocity) && inL.mActive == inR.mActive;
}

/// A pile of boxes and spheres falling onto a floor and a ramp, in several heaps (several islands, some
/// falling asleep, some woken by late arrivals), stepped 600 times.
std::vector<BodyState> RunPile(uint32_t inThreads, bool inUpdateBesideStep = false)
{
    std::unique_ptr<jobs::JobSystem> jobSystem;
    if (inThreads > 0)
    {
        jobs::JobSystem::Settings settings;
        settings.mNumThreads = inThreads;
        jobSystem = std::make_unique<jobs::JobSystem>(settings);
    }
    PhysicsSettings physicsSettings;
    // The broad-phase rebuild beside the pair search on this small scene too (by default from 1,024 bodies)
    if (inUpdateBesideStep) physicsSettings.mUpdateBesideStepMinActiveBodies = 0;
    PhysicsSystem system(physicsSettings);
    BodyInterface& bodies = system.GetBodyInterface();
    const BodyCreationSettings floor = test::StaticFloorSettings(40.0f);
    (void)bodies.CreateAndAddBody(floor, Activation::DontActivate);
    BodyCreationSettings ramp = floor;
    ramp.mShape = BoxShape::Create(Vec3(6, 0.5f, 6)).Value();
    ramp.mPosition = Vec3(15, 2, 0);
    ramp.mRotation = Quat(Eigen::AngleAxisf(0.4f, Vec3::UnitZ()));
    (void)bodies.CreateAndAddBody(ramp, Activation::DontActivate);

    std::vector<BodyID> ids;
    const ShapeRef box = BoxShape::Create(Vec3(0.4f, 0.4f, 0.4f)).Value();
    const ShapeRef ball = SphereShape::Create(0.35f).Value();
    for (int heap = 0; heap < 4; ++heap)
        for (int i = 0; i < 80; ++i)
        {
            BodyCreationSettings settings;
            settings.mShape = (i % 3 == 0) ? ball : box;
            const float x = -15.0f + 10.0f * float(heap) + 0.3f * float(i % 4);
            settings.mPosition =
                Vec3(x, 0.5f + 0.9f * float(i / 4) + 0.2f * float(heap), 0.25f * float(i % 5));
            settings.mRotation = Quat(Eigen::AngleAxisf(0.13f * float(i), Vec3(1, 2, 0.5f).normalized()));
            settings.mMotionType = MotionType::Dynamic;
            settings.mObjectLayer = Layers::cMoving;
            ids.push_back(bodies.CreateAndAddBody(settings, Activation::Activate).Value());
        }
    for (int step = 0; step < 600; ++step)
    {
        const Status status =
            jobSystem ? system.Update(1.0f / 60.0f, 1, *jobSystem) : system.Update(1.0f / 60.0f);
        EXPECT_TRUE(status.IsOk());
        if (step == 400)
        {
            // A late arrival wakes a heap that may have gone to sleep
            BodyCreationSettings late;
            late.mShape = box;
            late.mPosition = Vec3(-15, 12, 0);
            late.mMotionType = MotionType::Dynamic;
            late.mObjectLayer = Layers::cMoving;
            ids.push_back(bodies.CreateAndAddBody(late, Activation::Activate).Value());
        }
    }
    std::vector<BodyState> states;
    for (const BodyID& id : ids)
        states.push_back({bodies.GetPosition(id).Value(), bodies.GetRotation(id).Value(),
                          bodies.GetLinearVelocity(id).Value(), bodies.GetAngularVelocity(id).Value(),
                          bodies.IsActive(id).Value()});
    return states;
}

void ExpectIdentical(const std::vector<BodyState>& inExpected, const std::vector<BodyState>& inActual,
                     const char* inWhat)
{
    ASSERT_EQ(inExpected.size(), inActual.size());
    int differing = 0;
    for (size_t i = 0; i < inExpected.size(); ++i)
        if (!BitIdentical(inExpected[i], inActual[i]) && ++differing <= 3)
            ADD_FAILURE() << inWhat << ": body " << i << " differs: position "
                          << inExpected[i].mPosition.transpose() << " vs "
                          << inActual[i].mPosition.transpose();
    EXPECT_EQ(differing, 0) << inWhat;
}

TEST(StepDeterminismTest, SameThreadCountGivesBitIdenticalStates)
{
    ExpectIdentical(RunPile(2), RunPile(2), "2 threads, two runs");
}

TEST(StepDeterminismTest, ThreadCountDoesNotChangeTheResult)
{
    const std::vector<BodyState> reference = RunPile(0);
    ExpectIdentical(reference, RunPile(1), "1 job thread vs no job system");
    ExpectIdentical(reference, RunPile(2), "2 threads vs no job system");
    ExpectIdentical(reference, RunPile(4), "4 threads vs no job system");
    ExpectIdentical(reference, RunPile(2, true),
                    "2 threads, broad-phase update beside the step, vs no job system");
}

} // namespace
} // namespace cairn::test
