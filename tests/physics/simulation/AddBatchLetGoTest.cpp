// An add batch that the game lets go of (destroys or overwrites) before finalizing or aborting it: it is
// aborted, wherever and whenever that happens, so its broad-phase state does not leak and its bodies do not
// stay pending for good (BodyInterface::AddBatch).

#include "SimulationFixture.h"
#include "cairn/physics/body/BodyLock.h"

#include <atomic>
#include <functional>
#include <optional>
#include <vector>

namespace cairn::test
{
namespace
{

class AddBatchLetGoTest : public SimulationFixture
{
protected:
    /// Dynamic spheres in a row, created but not in the world
    std::vector<BodyID> CreateBodies(int inCount, float inZ = 0.0f)
    {
        std::vector<BodyID> ids;
        for (int i = 0; i < inCount; ++i)
            ids.push_back(Bodies().CreateBody(DynamicSettings(Sphere(0.4f), Vec3(float(i), 5, inZ))).Value());
        return ids;
    }

    bool IsFoundByTheBroadPhase(const BodyID& inID)
    {
        bool found = false;
        System().GetBroadPhase().CollidePoint(Position(inID), {},
                                              [&](BodyID inHit) { found |= inHit == inID; });
        return found;
    }
};

TEST_F(AddBatchLetGoTest, ABatchLetGoIsAbortedAndItsBodiesCanBeBatchedAgain)
{
    // A small world: its broad phase has nodes for a few dozen such batches only, so leaked states run it out
    PhysicsSettings settings;
    settings.mMaxBodies = 256;
    ResetWorld(settings);
    const std::vector<BodyID> ids = CreateBodies(64);
    for (int round = 0; round < 200; ++round)
    {
        Result<BodyInterface::AddBatch> batch = Bodies().AddBodiesPrepare(ids);
        ASSERT_TRUE(batch.IsOk()) << "round " << round << ": " << batch.GetError().mMessage;
        ASSERT_EQ(batch.Value().GetNumBodies(), ids.size());
    }
    Result<BodyInterface::AddBatch> batch = Bodies().AddBodiesPrepare(ids);
    ASSERT_TRUE(batch.IsOk());
    ASSERT_TRUE(Bodies().AddBodiesFinalize(batch.Value(), Activation::DontActivate).IsOk());
    for (const BodyID& id : ids)
        EXPECT_TRUE(IsFoundByTheBroadPhase(id));
    EXPECT_EQ(System().GetBroadPhase().GetBodyCount(), ids.size()) << "no body of a dropped batch was linked";
}

TEST_F(AddBatchLetGoTest, MovingABatchOverAPreparedOneAbortsTheOverwrittenOne)
{
    const std::vector<BodyID> first = CreateBodies(3, 0.0f);
    const std::vector<BodyID> second = CreateBodies(3, 4.0f);
    Result<BodyInterface::AddBatch> kept = Bodies().AddBodiesPrepare(first);
    Result<BodyInterface::AddBatch> other = Bodies().AddBodiesPrepare(second);
    ASSERT_TRUE(kept.IsOk() && other.IsOk());
    kept.Value() = std::move(other.Value());
    EXPECT_TRUE(other.Value().IsEmpty());
    for (const BodyID& id : first)
        EXPECT_TRUE(Bodies().AddBody(id, Activation::DontActivate).IsOk())
            << "the overwritten batch let it go";
    ASSERT_TRUE(Bodies().AddBodiesFinalize(kept.Value(), Activation::DontActivate).IsOk());
    for (const BodyID& id : second)
        EXPECT_TRUE(IsFoundByTheBroadPhase(id));
    EXPECT_TRUE(Bodies().AddBodiesAbort(other.Value()).IsOk()) << "a moved-from batch is finished";
}

/// Lets go of a batch from inside the step, on whichever job thread first reports a contact
class LetGoOnContact : public ContactListener
{
public:
    explicit LetGoOnContact(BodyInterface::AddBatch&& ioBatch) : mBatch(std::move(ioBatch)) {}

    void OnContactAdded(const Body&, const Body&, const ContactManifold&, ContactSettings&) override
    {
        // Relaxed: the exchange alone makes one thread the only one to touch mBatch; the step's return orders
        // that before the test reads anything
        if (!mLetGo.exchange(true, std::memory_order_relaxed)) mBatch.reset();
    }
    bool HasLetGo() const
    {
        return mLetGo.load(std::memory_order_relaxed); // Relaxed: read after the step returned, see above
    }

private:
    std::optional<BodyInterface::AddBatch> mBatch;
    std::atomic<bool> mLetGo{false};
};

TEST_F(AddBatchLetGoTest, ABatchLetGoInsideTheStepIsAbortedByTheNextCallThatNeedsItsBodies)
{
    AddFloor();
    AddDynamic(DynamicSettings(Sphere(0.5f), Vec3(0, 0.49f, 0))); // Touches the floor in the first step
    const std::vector<BodyID> ids = CreateBodies(4, 10.0f);
    Result<BodyInterface::AddBatch> batch = Bodies().AddBodiesPrepare(ids);
    ASSERT_TRUE(batch.IsOk());
    LetGoOnContact listener(std::move(batch.Value()));
    System().SetContactListener(&listener);
    Step(1);
    System().SetContactListener(nullptr);
    ASSERT_TRUE(listener.HasLetGo());
    // Inside the step its bodies could not be locked: the abort waited for these calls
    EXPECT_TRUE(Bodies().AddBody(ids[0], Activation::Activate).IsOk());
    EXPECT_TRUE(Bodies().DestroyBody(ids[1]).IsOk());
    Result<BodyInterface::AddBatch> again = Bodies().AddBodiesPrepare({ids.data() + 2, 2});
    ASSERT_TRUE(again.IsOk());
    EXPECT_TRUE(Bodies().AddBodiesFinalize(again.Value(), Activation::Activate).IsOk());
    EXPECT_TRUE(IsFoundByTheBroadPhase(ids[3]));
}

TEST_F(AddBatchLetGoTest, ABatchLetGoUnderABodyLockIsAbortedByEachCallThatNeedsItsBodies)
{
    const BodyID floor = AddFloor();
    // Each of these needs the body free of its batch: it fails while the batch holds it
    const std::vector<std::pair<const char*, std::function<Status(const BodyID&)>>> calls{
        {"AddBody", [&](const BodyID& inID) { return Bodies().AddBody(inID, Activation::Activate); }},
        {"DestroyBody", [&](const BodyID& inID) { return Bodies().DestroyBody(inID); }},
        {"SetObjectLayer",
         [&](const BodyID& inID) { return Bodies().SetObjectLayer(inID, Layers::cDebris); }},
        {"AddBodiesPrepare",
         [&](const BodyID& inID)
         {
             Result<BodyInterface::AddBatch> again = Bodies().AddBodiesPrepare({&inID, 1});
             return again ? Bodies().AddBodiesFinalize(again.Value(), Activation::Activate)
                          : again.GetError();
         }},
    };
    for (const auto& [name, call] : calls)
    {
        const std::vector<BodyID> ids = CreateBodies(1);
        {
            Result<BodyInterface::AddBatch> batch = Bodies().AddBodiesPrepare(ids);
            ASSERT_TRUE(batch.IsOk());
            BodyLockRead lock(System().GetBodyManager(), floor);
            ASSERT_TRUE(lock.Succeeded());
            batch.Value() = BodyInterface::AddBatch(); // Let go while this thread holds a body lock
            // The deferred abort must not run here either: it would lock the batch's bodies
            EXPECT_EQ(call(ids[0]).GetError().mCode, ErrorCode::WrongThread) << name;
        }
        EXPECT_TRUE(call(ids[0]).IsOk()) << name << " found the body still in its batch";
    }
}

TEST_F(AddBatchLetGoTest, ABatchDeferredAndNeverAbortedIsFreedWithItsWorld)
{
    std::unique_ptr<PhysicsSystem> world = MakePhysicsSystem();
    BodyInterface& bodies = world->GetBodyInterface();
    const BodyID floor =
        bodies.CreateAndAddBody(DynamicSettings(Box(Vec3(5, 1, 5)), Vec3(0, -1, 0)), Activation::DontActivate)
            .Value();
    const BodyID id = bodies.CreateBody(DynamicSettings(Sphere(1), Vec3(0, 5, 0))).Value();
    {
        Result<BodyInterface::AddBatch> batch = bodies.AddBodiesPrepare({&id, 1});
        ASSERT_TRUE(batch.IsOk());
        BodyLockRead lock(world->GetBodyManager(), floor);
        ASSERT_TRUE(lock.Succeeded());
        batch.Value() = BodyInterface::AddBatch();
    }
    // No call of the world's aborted the deferred batch: the world does as it goes (a leak otherwise, which
    // the sanitizer build of this test sees)
    world.reset();
}

TEST_F(AddBatchLetGoTest, ABatchThatOutlivesItsWorldIsRefusedElsewhereAndLetGoSafely)
{
    std::optional<BodyInterface::AddBatch> orphan;
    {
        std::unique_ptr<PhysicsSystem> gone = MakePhysicsSystem();
        const BodyID id =
            gone->GetBodyInterface().CreateBody(DynamicSettings(Sphere(1), Vec3(0, 5, 0))).Value();
        Result<BodyInterface::AddBatch> batch = gone->GetBodyInterface().AddBodiesPrepare({&id, 1});
        ASSERT_TRUE(batch.IsOk());
        orphan.emplace(std::move(batch.Value()));
    }
    // The world freed the batch's broad-phase state as it went (a leak or a use after free otherwise: the
    // sanitizer build of this test sees either)
    EXPECT_EQ(Bodies().AddBodiesFinalize(*orphan, Activation::Activate).GetError().mCode,
              ErrorCode::InvalidArgument);
    EXPECT_EQ(Bodies().AddBodiesAbort(*orphan).GetError().mCode, ErrorCode::InvalidArgument);
    orphan.reset();
    EXPECT_EQ(System().GetBroadPhase().GetBodyCount(), 0u);
}

} // namespace
} // namespace cairn::test
