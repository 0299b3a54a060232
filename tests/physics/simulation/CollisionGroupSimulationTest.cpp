// Collision groups in the step (issue 33): two overlapping parts of one object that its table keeps apart
// rest overlapping; the same boxes in two objects push apart; a part beyond its table is refused.

#include "SimulationFixture.h"

namespace cairn::test
{
namespace
{

class CollisionGroupTest : public SimulationFixture
{
protected:
    /// Two 1 m boxes on the floor, overlapping by 0.7 m in x, in the groups given
    std::pair<BodyID, BodyID> AddOverlappingPair(const CollisionGroup& inA, const CollisionGroup& inB)
    {
        AddFloor();
        BodyCreationSettings a = DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0.0f, 0.5f, 0.0f));
        a.mCollisionGroup = inA;
        BodyCreationSettings b = DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0.3f, 0.5f, 0.0f));
        b.mCollisionGroup = inB;
        return {AddDynamic(a), AddDynamic(b)};
    }
};

TEST_F(CollisionGroupTest, PartsTheirTableKeepsApartRestOverlappingAndOtherObjectsPushApart)
{
    auto table = std::make_shared<GroupFilterTable>(2);
    table->DisableCollision(0, 1);
    {
        const auto [a, b] = AddOverlappingPair({table, 1, 0}, {table, 1, 1});
        Step(60);
        EXPECT_NEAR(Position(b).x() - Position(a).x(), 0.3f, 0.001f);
        EXPECT_NEAR(Position(a).y(), 0.5f, 0.01f); // Both on the floor: the floor is no part of the group
        EXPECT_NEAR(Position(b).y(), 0.5f, 0.01f);
    }
    ResetWorld(PhysicsSettings{});
    {
        const auto [a, b] = AddOverlappingPair({table, 1, 0}, {table, 2, 1}); // Two objects
        Step(60);
        EXPECT_GT(Position(b).x() - Position(a).x(), 0.9f);
    }
}

TEST_F(CollisionGroupTest, APartBeyondItsTableIsRefused)
{
    BodyCreationSettings settings = DynamicSettings(Box(Vec3(0.5f, 0.5f, 0.5f)), Vec3(0.0f, 0.5f, 0.0f));
    settings.mCollisionGroup = {std::make_shared<GroupFilterTable>(2), 1, 2};
    EXPECT_EQ(Bodies().CreateBody(settings).GetError().mCode, ErrorCode::InvalidArgument);
}

} // namespace
} // namespace cairn::test
