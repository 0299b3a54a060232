// Collision groups (issue 33, ragdolls): a group's table lets every pair of parts collide until told
// otherwise, either way round; bodies of different groups or of none always may; one group with no table
// keeps its parts apart.

#include "cairn/physics/body/CollisionGroup.h"

#include <gtest/gtest.h>

namespace cairn::physics
{
namespace
{

TEST(GroupFilterTableTest, PairsCollideUntilDisabledEitherWayRound)
{
    GroupFilterTable table(70); // Pairs past one 64-bit word
    EXPECT_TRUE(table.CanCollide(3, 65));
    table.DisableCollision(65, 3);
    EXPECT_FALSE(table.CanCollide(3, 65));
    EXPECT_FALSE(table.CanCollide(65, 3));
    EXPECT_TRUE(table.CanCollide(3, 64)); // Its neighbours untouched
    EXPECT_TRUE(table.CanCollide(2, 65));
    EXPECT_TRUE(table.CanCollide(68, 69));
    table.DisableCollision(68, 69); // The last pair
    EXPECT_FALSE(table.CanCollide(69, 68));
    table.EnableCollision(3, 65);
    EXPECT_TRUE(table.CanCollide(65, 3));
    // Out of range: ignored when set, colliding when asked
    table.DisableCollision(1, 700);
    EXPECT_TRUE(table.CanCollide(1, 700));
    EXPECT_EQ(GroupFilterTable(0).GetNumSubGroups(), 1u);
    EXPECT_EQ(GroupFilterTable(1u << 30).GetNumSubGroups(), GroupFilterTable::cMaxSubGroups);
}

TEST(GroupFilterTableTest, GroupsDecideOnlyWithinOneGroup)
{
    auto table = std::make_shared<GroupFilterTable>(3);
    table->DisableCollision(0, 1);
    const CollisionGroup upperArm{table, 7, 0}, lowerArm{table, 7, 1}, hand{table, 7, 2};
    EXPECT_FALSE(GroupsCollide(upperArm, lowerArm));
    EXPECT_TRUE(GroupsCollide(upperArm, hand));
    const CollisionGroup otherRagdoll{table, 8, 1}, none;
    EXPECT_TRUE(GroupsCollide(upperArm, otherRagdoll));
    EXPECT_TRUE(GroupsCollide(upperArm, none));
    EXPECT_TRUE(GroupsCollide(none, none));
    const CollisionGroup noTableA{nullptr, 9, 0}, noTableB{nullptr, 9, 1};
    EXPECT_FALSE(GroupsCollide(noTableA, noTableB));
}

} // namespace
} // namespace cairn::physics
