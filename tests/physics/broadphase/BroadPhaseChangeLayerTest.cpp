// BroadPhase::ChangeBodyLayer on every broad phase: the body moves to the new object layer (and, in the quad
// tree, to the new layer's tree) for queries and pairs, the callback runs once while it happens, bad input
// changes nothing, and the quad tree stays valid. Every case runs before and after Update(), as in
// BroadPhaseCasesTest. The no-miss property under concurrent queries is tests/concurrency/LiveBodyChangeTest.

#include "physics/broadphase/BroadPhaseKinds.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <memory>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

using test::cA;
using test::cB;
using test::cC;
using test::cUnitBox;

ObjectLayerMask Only(ObjectLayer inLayer)
{
    return ObjectLayerMask(1) << inLayer;
}

template <class T> class BroadPhaseChangeLayerTest : public ::testing::Test
{
protected:
    void SetUp() override { mBroadPhase = test::MakeBroadPhase<T>(); }

    void Add(std::initializer_list<BroadPhaseBody> inBodies)
    {
        const std::vector<BroadPhaseBody> bodies(inBodies);
        mBroadPhase->AddBodiesFinalize(mBroadPhase->AddBodiesPrepare(bodies));
    }
    /// Every report of a box query (a body reported twice appears twice).
    std::vector<BodyID> Box(const AABB& inBox, ObjectLayerMask inMask = cAllObjectLayers) const
    {
        std::vector<BodyID> hits;
        mBroadPhase->CollideAABox(inBox, {inMask}, [&](BodyID inID) { hits.push_back(inID); });
        std::sort(hits.begin(), hits.end());
        return hits;
    }
    std::vector<BodyID> Ray(const Vec3& inOrigin, const Vec3& inDirection, ObjectLayerMask inMask) const
    {
        std::vector<BodyID> hits;
        mBroadPhase->CastRay({inOrigin, inDirection}, {inMask},
                             [&](BodyID inID, float)
                             {
                                 hits.push_back(inID);
                                 return 1.0f;
                             });
        std::sort(hits.begin(), hits.end());
        return hits;
    }
    std::vector<std::pair<BodyID, BodyID>> Pairs(std::initializer_list<BodyID> inActive) const
    {
        std::vector<std::pair<BodyID, BodyID>> pairs;
        const std::vector<BodyID> active(inActive);
        mBroadPhase->FindCollidingPairs(active, LayerSetup::CreateDefault(),
                                        [&](BodyID inA, BodyID inB) { pairs.emplace_back(inA, inB); });
        std::sort(pairs.begin(), pairs.end());
        return pairs;
    }
    /// ChangeBodyLayer, counting the callback's runs in mCallbacks.
    bool Change(BodyID inID, ObjectLayer inLayer)
    {
        return mBroadPhase->ChangeBodyLayer(inID, inLayer, [&] { ++mCallbacks; });
    }
    /// The quad tree's own check, for the implementations that have one.
    bool IsValid() const
    {
        if (const auto* quadTree = dynamic_cast<const BroadPhaseQuadTree*>(mBroadPhase.get()))
            return quadTree->Validate();
        if (const auto* wrapper = dynamic_cast<const BroadPhaseGlobalMutex*>(mBroadPhase.get()))
            if (const auto* quadTree = dynamic_cast<const BroadPhaseQuadTree*>(&wrapper->GetWrapped()))
                return quadTree->Validate();
        return true;
    }

    std::unique_ptr<BroadPhase> mBroadPhase;
    int mCallbacks = 0;
};

TYPED_TEST_SUITE(BroadPhaseChangeLayerTest, test::BroadPhaseKinds);

TYPED_TEST(BroadPhaseChangeLayerTest, BodyMovesToTheOtherBroadPhaseLayerAndBack)
{
    // A on the static layer, B (debris: collides with static only) overlapping it, C far away
    const AABB far(Vec3(20, 0, 20), Vec3(21, 1, 21));
    this->Add({{cA, cUnitBox, Layers::cStatic},
               {cB, AABB(Vec3(0.5f, 0, 0), Vec3(1.5f, 1, 1)), Layers::cDebris},
               {cC, far, Layers::cMoving}});
    for (int pass = 0; pass < 2; ++pass)
    {
        if (pass == 1) this->mBroadPhase->Update();
        this->mCallbacks = 0;
        EXPECT_EQ(this->Pairs({cB}), (std::vector<std::pair<BodyID, BodyID>>{{cB, cA}}));
        // To the moving layer (the other broad-phase layer): found there only, once, and debris no longer
        // collides with it
        ASSERT_TRUE(this->Change(cA, Layers::cMoving));
        EXPECT_EQ(this->mCallbacks, 1);
        EXPECT_EQ(this->Box(cUnitBox, Only(Layers::cMoving)), std::vector<BodyID>{cA});
        EXPECT_TRUE(this->Box(cUnitBox, Only(Layers::cStatic)).empty());
        EXPECT_EQ(this->Box(cUnitBox), (std::vector<BodyID>{cA, cB}));
        EXPECT_EQ(this->Ray(Vec3(-1, 0.5f, 0.25f), Vec3(3, 0, 0), cAllObjectLayers),
                  (std::vector<BodyID>{cA, cB}));
        EXPECT_TRUE(this->Pairs({cB}).empty());
        EXPECT_EQ(this->mBroadPhase->GetBodyCount(), 3u);
        EXPECT_TRUE(this->IsValid());
        // Moves and removes find it in its new layer
        const BroadPhaseBody moved{cA, AABB(Vec3(0, 2, 0), Vec3(1, 3, 1)), Layers::cMoving};
        this->mBroadPhase->NotifyBodiesAABBChanged({&moved, 1});
        EXPECT_EQ(this->Box(moved.mBounds), std::vector<BodyID>{cA});
        EXPECT_TRUE(this->Box(cUnitBox, Only(Layers::cMoving)).empty());
        const BroadPhaseBody back{cA, cUnitBox, Layers::cMoving};
        this->mBroadPhase->NotifyBodiesAABBChanged({&back, 1});
        // And back to static
        ASSERT_TRUE(this->Change(cA, Layers::cStatic));
        EXPECT_EQ(this->mCallbacks, 2);
        EXPECT_EQ(this->Box(cUnitBox, Only(Layers::cStatic)), std::vector<BodyID>{cA});
        EXPECT_TRUE(this->Box(cUnitBox, Only(Layers::cMoving)).empty());
        EXPECT_EQ(this->Pairs({cB}), (std::vector<std::pair<BodyID, BodyID>>{{cB, cA}}));
        EXPECT_EQ(this->mBroadPhase->GetBodyCount(), 3u);
        EXPECT_TRUE(this->IsValid());
    }
    this->mBroadPhase->RemoveBodies({&cA, 1});
    EXPECT_TRUE(this->Box(cUnitBox, Only(Layers::cStatic)).empty());
    EXPECT_EQ(this->mBroadPhase->GetBodyCount(), 2u);
    EXPECT_TRUE(this->IsValid());
}

TYPED_TEST(BroadPhaseChangeLayerTest, BodyChangesLayerWithinOneBroadPhaseLayer)
{
    // Moving and debris share the moving broad-phase layer; a static body under B
    this->Add({{cA, cUnitBox, Layers::cStatic}, {cB, cUnitBox, Layers::cMoving}});
    for (int pass = 0; pass < 2; ++pass)
    {
        if (pass == 1) this->mBroadPhase->Update();
        ASSERT_TRUE(this->Change(cB, Layers::cDebris));
        EXPECT_EQ(this->Box(cUnitBox, Only(Layers::cDebris)), std::vector<BodyID>{cB});
        EXPECT_TRUE(this->Box(cUnitBox, Only(Layers::cMoving)).empty());
        EXPECT_EQ(this->Box(cUnitBox), (std::vector<BodyID>{cA, cB}));
        // Trigger collides with nothing: no pair with the static body any more
        ASSERT_TRUE(this->Change(cB, Layers::cTrigger));
        EXPECT_TRUE(this->Pairs({cB}).empty());
        ASSERT_TRUE(this->Change(cB, Layers::cMoving));
        EXPECT_EQ(this->Pairs({cB}), (std::vector<std::pair<BodyID, BodyID>>{{cB, cA}}));
        EXPECT_TRUE(this->IsValid());
    }
    EXPECT_EQ(this->mCallbacks, 6);
}

TYPED_TEST(BroadPhaseChangeLayerTest, ManyBodiesChangeTreesAndStayFoundOnce)
{
    // A grid of bodies, every other one sent to the other broad-phase layer, some twice, with updates between
    std::vector<BroadPhaseBody> bodies;
    for (uint32_t i = 0; i < 200; ++i)
    {
        const Vec3 p(float(i % 20) * 2.0f, 0.0f, float(i / 20) * 2.0f);
        bodies.push_back(
            {BodyID(i, 3), AABB(p, p + Vec3::Constant(1.0f)), i % 3 ? Layers::cMoving : Layers::cStatic});
    }
    this->mBroadPhase->AddBodiesFinalize(this->mBroadPhase->AddBodiesPrepare(bodies));
    for (int round = 0; round < 3; ++round)
    {
        for (BroadPhaseBody& body : bodies)
            if ((body.mID.GetIndex() + uint32_t(round)) % 2 == 0)
            {
                body.mLayer = body.mLayer == Layers::cStatic ? Layers::cMoving : Layers::cStatic;
                ASSERT_TRUE(this->Change(body.mID, body.mLayer));
            }
        if (round == 1) this->mBroadPhase->Update();
        for (const BroadPhaseBody& body : bodies)
        {
            EXPECT_EQ(this->Box(body.mBounds.Expanded(-0.1f)), std::vector<BodyID>{body.mID});
            EXPECT_EQ(this->Box(body.mBounds.Expanded(-0.1f), Only(body.mLayer)),
                      std::vector<BodyID>{body.mID});
        }
        EXPECT_EQ(this->mBroadPhase->GetBodyCount(), bodies.size());
        EXPECT_TRUE(this->IsValid());
    }
}

TYPED_TEST(BroadPhaseChangeLayerTest, BadInputChangesNothing)
{
    this->Add({{cA, cUnitBox, Layers::cStatic}});
    // The same layer: nothing to move, the callback still runs (the caller publishes in it)
    EXPECT_TRUE(this->Change(cA, Layers::cStatic));
    EXPECT_EQ(this->mCallbacks, 1);
    // Absent or stale ids: refused, no callback
    EXPECT_FALSE(this->Change(cB, Layers::cMoving));
    EXPECT_FALSE(this->Change(BodyID(1, 2), Layers::cMoving));
    EXPECT_EQ(this->mCallbacks, 1);
    // An object layer no broad phase knows: assert in debug, refused in release
    EXPECT_DEBUG_DEATH(EXPECT_FALSE(this->Change(cA, ObjectLayer(200))), "");
    EXPECT_EQ(this->mCallbacks, 1);
    EXPECT_EQ(this->Box(cUnitBox, Only(Layers::cStatic)), std::vector<BodyID>{cA});
    EXPECT_EQ(this->mBroadPhase->GetBodyCount(), 1u);
    EXPECT_TRUE(this->IsValid());
}

} // namespace
} // namespace cairn
