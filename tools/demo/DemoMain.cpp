// cairn-demo: until the streaming open-world demo lands, a small physics scene (stacks knocked over by a rain
// of spheres and a kinematic sweeper) that steps at 60 Hz and prints its frame times.

#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "common/FrameTimes.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

using namespace cairn;

namespace
{
struct Options
{
    int mFrames = 600;
    int mCollisionSteps = 1;
};

void PrintHelp()
{
    std::printf(
        "usage: cairn-demo [--frames N] [--collision-steps N] [--help]\n"
        "  Steps a small scene (box stacks, falling spheres and capsules, a kinematic sweeper) at 60 Hz\n"
        "  and prints physics frame times.\n");
}

/// Parses the flags; exits with a message on bad input.
Options ParseOptions(int inArgc, char** inArgv)
{
    Options options;
    for (int i = 1; i < inArgc; ++i)
    {
        const std::string flag = inArgv[i];
        auto value = [&](int inMin, int inMax)
        {
            if (i + 1 >= inArgc)
            {
                std::fprintf(stderr, "cairn-demo: %s needs a value\n", flag.c_str());
                std::exit(2);
            }
            char* end = nullptr;
            const long parsed = std::strtol(inArgv[++i], &end, 10);
            if (*end != '\0' || parsed < inMin || parsed > inMax)
            {
                std::fprintf(stderr, "cairn-demo: %s must be a whole number in [%d, %d]\n", flag.c_str(),
                             inMin, inMax);
                std::exit(2);
            }
            return int(parsed);
        };
        if (flag == "--help" || flag == "-h")
        {
            PrintHelp();
            std::exit(0);
        }
        else if (flag == "--frames")
            options.mFrames = value(1, 1000000);
        else if (flag == "--collision-steps")
            options.mCollisionSteps = value(1, 16);
        else
        {
            std::fprintf(stderr, "cairn-demo: unknown flag '%s' (see --help)\n", flag.c_str());
            std::exit(2);
        }
    }
    return options;
}

BodyID Add(BodyInterface& ioBodies, const ShapeRef& inShape, const Vec3& inPosition, MotionType inMotion)
{
    BodyCreationSettings settings;
    settings.mShape = inShape;
    settings.mPosition = inPosition;
    settings.mMotionType = inMotion;
    settings.mObjectLayer = inMotion == MotionType::Static ? Layers::cStatic : Layers::cMoving;
    settings.mFriction = 0.5f;
    return ioBodies.CreateAndAddBody(settings, Activation::Activate).Value();
}
} // namespace

int main(int inArgc, char** inArgv)
{
    const Options options = ParseOptions(inArgc, inArgv);
    PhysicsSystem system;
    BodyInterface& bodies = system.GetBodyInterface();

    Add(bodies, BoxShape::Create(Vec3(60, 1, 60)).Value(), Vec3(0, -1, 0), MotionType::Static);
    const ShapeRef crate = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    for (int stack = 0; stack < 16; ++stack)
        for (int level = 0; level < 8; ++level)
            Add(bodies, crate,
                Vec3(-24.0f + 3.0f * float(stack), 0.5f + float(level), 4.0f * float(stack % 3)),
                MotionType::Dynamic);
    BodyCreationSettings sweeper;
    sweeper.mShape = CapsuleShape::Create(8.0f, 0.6f).Value();
    sweeper.mPosition = Vec3(-30, 0.6f, 4);
    sweeper.mRotation = Quat(Eigen::AngleAxisf(0.5f * cPi, Vec3::UnitX()));
    sweeper.mMotionType = MotionType::Kinematic;
    sweeper.mLinearVelocity = Vec3(4, 0, 0);
    (void)bodies.CreateAndAddBody(sweeper, Activation::Activate);
    const ShapeRef ball = SphereShape::Create(0.3f).Value();

    std::vector<double> frameMs;
    frameMs.reserve(size_t(options.mFrames));
    for (int frame = 0; frame < options.mFrames; ++frame)
    {
        if (frame % 10 == 0 && frame < 400)
            Add(bodies, ball, Vec3(-20.0f + float(frame % 40), 15.0f, float(frame % 7)), MotionType::Dynamic);
        const auto start = std::chrono::steady_clock::now();
        if (Status status = system.Update(1.0f / 60.0f, options.mCollisionSteps); !status)
        {
            std::fprintf(stderr, "cairn-demo: step failed: %s\n", status.GetError().mMessage.c_str());
            return 1;
        }
        frameMs.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        if ((frame + 1) % 100 == 0)
        {
            const StepStatistics& stats = system.GetLastStepStatistics();
            std::printf("frame %5d  %6.3f ms  active %4u  pairs-manifolds %5u  islands %4u\n", frame + 1,
                        frameMs.back(), stats.mNumActiveBodies, stats.mNumManifolds, stats.mNumIslands);
        }
    }
    const tools::TimingSummary summary = tools::Summarize(frameMs);
    std::printf(
        "\nphysics frame time over %d frames (1/60 s, %d collision step(s)): mean %.3f ms, p50 %.3f ms, "
        "p99 %.3f ms, max %.3f ms\n",
        options.mFrames, options.mCollisionSteps, summary.mMean, summary.mP50, summary.mP99, summary.mMax);
    return 0;
}
