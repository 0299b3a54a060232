// cairn-bench-characters: CharacterController Updates in a CharacterGroup against the same walk in none.
//  char_group_<N>  N characters (capsules, 1.8 m tall) walking straight on a floor, one per 4 m², in random
//                  directions, 100 frames at 60 Hz after 20 to settle, one thread: µs per Update in no group
//                  (they pass through each other) and in one group (they block each other), the group's
//                  Publish (its grid rebuilt) in ms, and the members' contacts at the end as the checksum.
// Own timers; medians over --repetitions.

#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/character/CharacterController.h"
#include "cairn/physics/character/CharacterGroup.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "common/BenchOptions.h"
#include "common/FrameTimes.h"
#include "common/PhysicsSystemOrExit.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <thread>
#include <vector>

using namespace cairn;
using namespace cairn::physics;
using Clock = std::chrono::steady_clock;

namespace
{

constexpr int cSettleFrames = 20, cFrames = 100;
constexpr float cDeltaTime = 1.0f / 60.0f;

struct WalkRun
{
    double mMicrosPerUpdate = 0.0;
    double mPublishMs = 0.0;
    long mMemberContacts = 0;
};

WalkRun Walk(int inCount, bool inGrouped)
{
    const std::unique_ptr<PhysicsSystem> world =
        tools::CreatePhysicsSystemOrExit("cairn-bench-characters", PhysicsSettings());
    BodyCreationSettings floor;
    floor.mShape = BoxShape::Create(Vec3(200, 1, 200)).Value();
    floor.mPosition = Vec3(0, -1, 0);
    floor.mMotionType = MotionType::Static;
    floor.mObjectLayer = Layers::cStatic;
    if (!world->GetBodyInterface().CreateAndAddBody(floor, Activation::DontActivate))
    {
        std::fprintf(stderr, "cairn-bench-characters: the floor was refused\n");
        std::exit(1);
    }
    (void)world->OptimizeBroadPhase();
    CharacterSettings settings;
    settings.mShape = CapsuleShape::Create(0.6f, 0.3f).Value();
    std::mt19937 random(7);
    const float side = 2.0f * std::sqrt(float(inCount));
    std::uniform_real_distribution<float> place(-side / 2.0f, side / 2.0f), direction(-1.0f, 1.0f);
    std::vector<CharacterController> characters;
    std::vector<Vec3> walks;
    characters.reserve(size_t(inCount));
    CharacterGroup group;
    for (int i = 0; i < inCount; ++i)
    {
        characters.push_back(
            CharacterController::Create(*world, settings, Vec3(place(random), 0.92f, place(random))).Value());
        walks.push_back(Vec3(direction(random), 0.0f, direction(random)).normalized() * 2.0f);
        if (inGrouped && !group.Add(characters.back()))
        {
            std::fprintf(stderr, "cairn-bench-characters: Add refused\n");
            std::exit(1);
        }
    }
    WalkRun run;
    double updateMs = 0.0;
    for (int frame = 0; frame < cSettleFrames + cFrames; ++frame)
    {
        const Clock::time_point start = Clock::now();
        for (int i = 0; i < inCount; ++i)
        {
            CharacterController& character = characters[size_t(i)];
            Vec3 velocity = walks[size_t(i)];
            velocity.y() = character.GetLinearVelocity().y();
            if (!character.SetLinearVelocity(velocity) || !character.Update(cDeltaTime, Vec3(0, -9.81f, 0)))
            {
                std::fprintf(stderr, "cairn-bench-characters: an Update was refused\n");
                std::exit(1);
            }
        }
        const Clock::time_point published = Clock::now();
        group.Publish();
        if (frame >= cSettleFrames)
        {
            updateMs += std::chrono::duration<double, std::milli>(published - start).count();
            run.mPublishMs += tools::MillisecondsSince(published) / double(cFrames);
        }
    }
    run.mMicrosPerUpdate = 1000.0 * updateMs / double(cFrames * inCount);
    for (const CharacterController& character : characters)
        run.mMemberContacts += long(character.GetCharacterContacts().size());
    return run;
}

} // namespace

int main(int argc, char** argv)
{
    tools::BenchOptions options;
    if (auto stop = tools::ParseBenchOptions(
            argc, argv, "cairn-bench-characters: character Updates in a group and in none",
            {"char_group_10", "char_group_100", "char_group_1000"}, options))
        return *stop;
    std::printf("cairn-bench-characters: %d repetitions, %u hardware threads\n", options.mRepetitions,
                std::thread::hardware_concurrency());
    for (const int count : {10, 100, 1000})
    {
        const std::string name = "char_group_" + std::to_string(count);
        if (!options.mOnly.empty() && options.mOnly != name) continue;
        std::vector<double> alone, grouped, publish;
        long contacts = 0;
        for (int rep = 0; rep < options.mRepetitions; ++rep)
        {
            alone.push_back(Walk(count, false).mMicrosPerUpdate);
            const WalkRun run = Walk(count, true);
            grouped.push_back(run.mMicrosPerUpdate);
            publish.push_back(run.mPublishMs);
            contacts = run.mMemberContacts;
        }
        std::printf(
            "%s median of %d: no group %.2f us an Update, one group %.2f us (%.2fx), Publish %.3f ms | "
            "checksum member contacts %ld\n",
            name.c_str(), options.mRepetitions, tools::Median(alone), tools::Median(grouped),
            tools::Median(grouped) / tools::Median(alone), tools::Median(publish), contacts);
    }
    return 0;
}
