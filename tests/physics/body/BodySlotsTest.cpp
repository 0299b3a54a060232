// BodyManager's slots: ids go out in index order with a freed slot first and its sequence one higher, a full
// manager says so, a slot's body is made when the slot is first used (a world of a large capacity writes
// none of the memory of the slots it has not used), and the bodies it made are destroyed with it.

#include "cairn/physics/body/BodyManager.h"
#include "cairn/physics/shapes/SphereShape.h"

#include <cstdio>
#include <gtest/gtest.h>
#include <unistd.h>

namespace cairn::physics
{
namespace
{

BodyCreationSettings SphereSettings(const ShapeRef& inShape)
{
    BodyCreationSettings settings;
    settings.mShape = inShape;
    settings.mMotionType = MotionType::Dynamic;
    return settings;
}

TEST(BodySlotsTest, SlotsGoOutInIndexOrderAFreedOneFirstWithTheNextSequence)
{
    const ShapeRef sphere = SphereShape::Create(0.5f).Value();
    BodyManager bodies(4);
    std::vector<BodyID> ids;
    for (int i = 0; i < 3; ++i)
        ids.push_back(bodies.CreateBody(SphereSettings(sphere)).Value());
    for (uint32_t i = 0; i < 3; ++i)
        EXPECT_EQ(ids[i], BodyID(i, 0));

    ASSERT_TRUE(bodies.DestroyBody(ids[1]).IsOk());
    EXPECT_EQ(bodies.CreateBody(SphereSettings(sphere)).Value(), BodyID(1, 1))
        << "the freed slot, a new sequence";
    EXPECT_EQ(bodies.CreateBody(SphereSettings(sphere)).Value(), BodyID(3, 0)) << "then the next slot";
    const Result<BodyID> full = bodies.CreateBody(SphereSettings(sphere));
    ASSERT_FALSE(full.IsOk());
    EXPECT_EQ(full.GetError().mCode, ErrorCode::OutOfCapacity);
    EXPECT_EQ(bodies.GetNumBodies(), 4u);

    // The stale id stays stale, and a slot freed twice comes back with the sequence after both
    EXPECT_FALSE(bodies.DestroyBody(ids[1]).IsOk());
    ASSERT_TRUE(bodies.DestroyBody(BodyID(1, 1)).IsOk());
    EXPECT_EQ(bodies.CreateBody(SphereSettings(sphere)).Value(), BodyID(1, 2));
    // A slot never handed out holds no body, and its id is unknown
    BodyManager fresh(8);
    EXPECT_EQ(fresh.TryGetBodyAtIndex(5), nullptr);
    EXPECT_EQ(fresh.DestroyBody(BodyID(5, 0)).GetError().mCode, ErrorCode::InvalidBodyID);
}

// The capacity is clamped into [1, PhysicsSettings::cMaxBodiesLimit], as the shard count is into its range:
// 2^32 slots threw bad_alloc (the top end is not made here: its storage is a quarter gigabyte)
TEST(BodySlotsTest, TheCapacityIsClampedIntoRange)
{
    EXPECT_EQ(BodyManager(0).GetMaxBodies(), 1u);
    EXPECT_EQ(BodyManager(5).GetMaxBodies(), 5u);
}

TEST(BodySlotsTest, TheBodiesMadeAreDestroyedWithTheManager)
{
    const ShapeRef sphere = SphereShape::Create(0.5f).Value();
    {
        BodyManager bodies(1000);
        for (int i = 0; i < 10; ++i)
            ASSERT_TRUE(bodies.CreateBody(SphereSettings(sphere)).IsOk());
        ASSERT_TRUE(bodies.DestroyBody(BodyID(4, 0)).IsOk()); // A freed slot keeps no shape
        EXPECT_GT(sphere.use_count(), 1);
    }
    EXPECT_EQ(sphere.use_count(), 1) << "a body the manager made still holds its shape";
}

/// This process's resident memory in bytes (Linux), or -1.
long ResidentBytes()
{
    std::FILE* statm = std::fopen("/proc/self/statm", "r");
    if (statm == nullptr) return -1;
    long size = 0, resident = -1;
    if (std::fscanf(statm, "%ld %ld", &size, &resident) != 2) resident = -1;
    std::fclose(statm);
    return resident < 0 ? -1 : resident * sysconf(_SC_PAGESIZE);
}

TEST(BodySlotsTest, AManagerWritesTheMemoryOfTheSlotsItUsedNotOfItsCapacity)
{
    // Resident memory rather than page faults: with transparent huge pages a written array may take a
    // fault per 2 MB, but it is resident all the same
    const long before = ResidentBytes();
    if (before < 0) GTEST_SKIP() << "no /proc/self/statm";
    constexpr uint32_t cSlots = 1u << 18;
    const ShapeRef sphere = SphereShape::Create(0.5f).Value();
    BodyManager bodies(cSlots);
    for (int i = 0; i < 100; ++i)
        ASSERT_TRUE(bodies.CreateBody(SphereSettings(sphere)).IsOk());
    const long grown = ResidentBytes() - before;
    // The published poses are written whole (a reader of any id needs a record), a cache line a slot; the
    // bodies' slots alone, if written, are four times that
    const long bodySlots = long(cSlots) * long(sizeof(Body));
    EXPECT_LT(grown, bodySlots / 2) << "grew " << grown / 1024 << " KiB for 100 bodies";
}

} // namespace
} // namespace cairn::physics
