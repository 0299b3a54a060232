// A query made while the step runs returns exactly what a brute-force query returns against the last
// published state, captured by the test.
//
// Threads:
//  - the step thread runs Update back to back on a closed box of moving dynamic bodies (boxes, spheres,
//    capsules and compounds, sleeping off, stirred by a spinning kinematic paddle) over a few static bodies
//    (a floor, walls, boxes, a sphere and a triangle-mesh patch). It sets the flag "stepping" around each
//    Update, and after each one returns (the step is the only publisher here, so nothing is published until
//    the next Update) it captures a snapshot: every body's published pose, read with a PoseReader, with a
//    generation number;
//  - two query threads each take the latest snapshot, run one random query (CastRayClosest, CastRayAll,
//    CollideSphere, CollideAABox, CollidePoint, or CastShapeAll or CastShapeClosest of a capsule, half of
//    them aimed at a body, half anywhere in the box),
//    then read every body's published version again. When every version still equals the snapshot's, nothing
//    was published between the capture and the end of the query, so the world the query saw is the snapshot:
//    its result must equal the brute-force answer over the snapshot, where each body is tested by the same
//    exact test WorldQuery makes (the shape's CastRay with the ray in local space; CollideShapes of the query
//    shape against the body's shape, deepest penetration >= 0; a zero-length CastRay from the point;
//    CastShapeAgainst with the queries' tolerance).
//    Overlap results are compared as sorted sets of ids; CastRayAll and CastShapeAll as lists of (body,
//    fraction, normal, sub-shape), exactly; CastRayClosest by its fraction, exactly, and its body, which must
//    be one of the bodies the brute force hits at that fraction (WorldQuery breaks ties by its own order);
//    CastShapeClosest by its body, which must be one the brute force hits, within the cast's tolerance of
//    the brute force's first touch and of its own fraction there (the search for the closest sweeps each
//    later body only up to the best fraction so far, which changes the manifolds it advances by).
// A comparison is "during a step" when the flag was set when the query started or when it ended: the step's
// broad-phase rebuild, pair search and solver ran beside the query. Queries whose snapshot went stale
// meanwhile are counted apart; the brute force is run on them too, and how often they differ shows that the
// comparison would see a query that answered from another state than the snapshot's. The random queries come
// from a seeded std::mt19937 per thread (RapidCheck's shrinking does not apply to a race; a mismatch is
// printed whole, with the snapshot poses of the bodies that differ).

#include "cairn/physics/PhysicsSystem.h"
#include "cairn/physics/body/PublishedPose.h"
#include "cairn/physics/narrowphase/CollideShapes.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/CompoundShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"
#include "common/MakePhysicsSystem.h"
#include "common/PublishedPoseStress.h"
#include "common/StaticFloor.h"
#include "narrowphase/ShapeCast.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <gtest/gtest.h>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

constexpr float cHalfBox = 10.0f; ///< Inner faces of the walls
constexpr float cRoofY = 6.0f;    ///< Underside of the roof

/// Every body's published pose after one Update, in the order of the test's ids.
struct Snapshot
{
    uint64_t mGeneration = 0;
    std::vector<PublishedPose> mPoses;
};

enum class QueryKind : int
{
    RayClosest,
    RayAll,
    Sphere,
    Box,
    Point,
    ShapeAll,
    ShapeClosest,
    Count
};

const char* KindName(QueryKind inKind)
{
    static const char* const names[] = {"CastRayClosest", "CastRayAll",   "CollideSphere",   "CollideAABox",
                                        "CollidePoint",   "CastShapeAll", "CastShapeClosest"};
    return names[int(inKind)];
}

/// One random query and its inputs.
struct Query
{
    QueryKind mKind = QueryKind::Point;
    RayCast mRay;                      ///< Also the shape cast's start and displacement
    Quat mRotation = Quat::Identity(); ///< The cast capsule's
    Vec3 mCenter = Vec3::Zero();       ///< Sphere centre or point
    float mRadius = 0.0f;
    AABB mBox;
};

/// What a query returned, in a form both sides of the comparison share.
struct Answer
{
    std::vector<BodyID> mBodies; ///< Overlap queries: sorted
    /// CastRayAll and CastShapeAll (its contact point and depth left out): sorted by fraction then body;
    /// CastRayClosest and CastShapeClosest: 0 or 1
    std::vector<RayCastResult> mHits;
};

/// Bit for bit: both sides compute a hit with the same operations on the same pose
bool SameHit(const RayCastResult& inA, const RayCastResult& inB)
{
    return inA.mBody == inB.mBody && inA.mFraction == inB.mFraction && inA.mNormal == inB.mNormal &&
           inA.mSubShape == inB.mSubShape;
}

bool SameAnswer(const Answer& inA, const Answer& inB)
{
    return inA.mBodies == inB.mBodies &&
           std::equal(inA.mHits.begin(), inA.mHits.end(), inB.mHits.begin(), inB.mHits.end(), SameHit);
}

std::string Describe(const Vec3& inV)
{
    char text[96];
    std::snprintf(text, sizeof(text), "(%.7g, %.7g, %.7g)", inV.x(), inV.y(), inV.z());
    return text;
}

std::string Describe(const Query& inQuery)
{
    std::string text = KindName(inQuery.mKind);
    switch (inQuery.mKind)
    {
    case QueryKind::RayClosest:
    case QueryKind::RayAll:
        return text + " origin " + Describe(inQuery.mRay.mOrigin) + " direction " +
               Describe(inQuery.mRay.mDirection);
    case QueryKind::ShapeAll:
    case QueryKind::ShapeClosest:
        return text + " start " + Describe(inQuery.mRay.mOrigin) + " rotation (" +
               std::to_string(inQuery.mRotation.w()) + ", " + Describe(inQuery.mRotation.vec()) +
               ") displacement " + Describe(inQuery.mRay.mDirection);
    case QueryKind::Sphere:
        return text + " centre " + Describe(inQuery.mCenter) + " radius " + std::to_string(inQuery.mRadius);
    case QueryKind::Box:
        return text + " min " + Describe(inQuery.mBox.mMin) + " max " + Describe(inQuery.mBox.mMax);
    default:
        return text + " point " + Describe(inQuery.mCenter);
    }
}

std::string Describe(const Answer& inAnswer)
{
    std::ostringstream text;
    text << "{";
    for (const BodyID& id : inAnswer.mBodies)
        text << " " << id.GetIndex();
    for (const RayCastResult& hit : inAnswer.mHits)
        text << " " << hit.mBody.GetIndex() << "@" << hit.mFraction << " n" << Describe(hit.mNormal);
    text << " }";
    return text.str();
}

/// The shape CastShapeAll and CastShapeClosest sweep: a capsule, turned by each query's rotation.
const Shape* CastShape()
{
    static const ShapeRef capsule = CapsuleShape::Create(0.3f, 0.25f).Value();
    return capsule.get();
}

/// The query against the world; false when it returned an error.
bool RunWorldQuery(const WorldQuery& inWorld, const Query& inQuery, Answer& outAnswer)
{
    outAnswer = {};
    switch (inQuery.mKind)
    {
    case QueryKind::RayClosest:
    {
        const Result<std::optional<RayCastResult>> hit = inWorld.CastRayClosest(inQuery.mRay);
        if (!hit) return false;
        if (hit.Value()) outAnswer.mHits.push_back(*hit.Value());
        return true;
    }
    case QueryKind::RayAll:
        return bool(inWorld.CastRayAll(inQuery.mRay, outAnswer.mHits));
    case QueryKind::ShapeAll:
    {
        thread_local std::vector<ShapeCastResult> hits;
        if (!inWorld.CastShapeAll(*CastShape(), {inQuery.mRay.mOrigin, inQuery.mRotation},
                                  inQuery.mRay.mDirection, hits))
            return false;
        for (const ShapeCastResult& hit : hits)
            outAnswer.mHits.push_back({hit.mBody, hit.mFraction, hit.mNormal, hit.mSubShape});
        return true;
    }
    case QueryKind::ShapeClosest:
    {
        const Result<std::optional<ShapeCastResult>> hit = inWorld.CastShapeClosest(
            *CastShape(), {inQuery.mRay.mOrigin, inQuery.mRotation}, inQuery.mRay.mDirection);
        if (!hit) return false;
        if (const std::optional<ShapeCastResult>& first = hit.Value())
            outAnswer.mHits.push_back({first->mBody, first->mFraction, first->mNormal, first->mSubShape});
        return true;
    }
    case QueryKind::Sphere:
        return bool(inWorld.CollideSphere(inQuery.mCenter, inQuery.mRadius, outAnswer.mBodies));
    case QueryKind::Box:
        return bool(inWorld.CollideAABox(inQuery.mBox, outAnswer.mBodies));
    default:
        return bool(inWorld.CollidePoint(inQuery.mCenter, outAnswer.mBodies));
    }
}

/// Hits in WorldQuery's order of cast results: by fraction, then by body.
void SortByFractionThenBody(std::vector<RayCastResult>& ioHits)
{
    std::sort(ioHits.begin(), ioHits.end(),
              [](const RayCastResult& inA, const RayCastResult& inB) {
                  return inA.mFraction < inB.mFraction ||
                         (inA.mFraction == inB.mFraction && inA.mBody < inB.mBody);
              });
}

/// Every body of the snapshot the ray hits, each with its closest hit, sorted by fraction then body: the ray
/// in the body's local space, as WorldQuery casts it.
std::vector<RayCastResult> BruteForceRay(const Snapshot& inSnapshot, const RayCast& inRay)
{
    std::vector<RayCastResult> hits;
    for (const PublishedPose& pose : inSnapshot.mPoses)
    {
        const RayCast local{pose.mTransform.InverseTransformPoint(inRay.mOrigin),
                            pose.mTransform.InverseRotateVector(inRay.mDirection)};
        RayHit hit;
        hit.mFraction = 1.0f + 1.0e-6f;
        if (!pose.mShape->CastRay(local, hit)) continue;
        hits.push_back({pose.mID, std::min(hit.mFraction, 1.0f), pose.mTransform.RotateVector(hit.mNormal),
                        hit.mSubShape});
    }
    SortByFractionThenBody(hits);
    return hits;
}

/// The bodies of the snapshot that inShape at inTransform touches (deepest penetration >= 0), sorted.
std::vector<BodyID> BruteForceShape(const Snapshot& inSnapshot, const Shape& inShape,
                                    const Transform& inTransform)
{
    std::vector<BodyID> bodies;
    CollideSettings settings;
    settings.mMaxSeparation = 0.0f;
    for (const PublishedPose& pose : inSnapshot.mPoses)
    {
        float deepest = -cLargeFloat;
        CollideShapes(inShape, inTransform, *pose.mShape, pose.mTransform, settings,
                      [&](const ContactManifold& inManifold)
                      {
                          for (int i = 0; i < inManifold.mNumPoints; ++i)
                              deepest = std::max(deepest, inManifold.mPoints[i].mPenetration);
                      });
        if (deepest >= 0.0f) bodies.push_back(pose.mID);
    }
    std::sort(bodies.begin(), bodies.end());
    return bodies;
}

/// Every body of the snapshot the cast capsule touches, where it first touches each, as WorldQuery sweeps it
/// (the same routine and tolerance), sorted by fraction then body.
std::vector<RayCastResult> BruteForceShapeCast(const Snapshot& inSnapshot, const Query& inQuery)
{
    std::vector<RayCastResult> hits;
    ShapeCastSettings settings;
    settings.mTolerance = QueryCastTolerance(inQuery.mRay.mOrigin);
    for (const PublishedPose& pose : inSnapshot.mPoses)
        if (const std::optional<ShapeCastHit> hit =
                CastShapeAgainst(*CastShape(), {inQuery.mRay.mOrigin, inQuery.mRotation},
                                 inQuery.mRay.mDirection, *pose.mShape, pose.mTransform, settings))
            hits.push_back({pose.mID, hit->mFraction, -hit->mManifold.mNormal, hit->mManifold.mSubShapeB});
    SortByFractionThenBody(hits);
    return hits;
}

/// The answer the world must give if it published exactly the snapshot.
Answer BruteForce(const Snapshot& inSnapshot, const Query& inQuery)
{
    Answer answer;
    switch (inQuery.mKind)
    {
    case QueryKind::RayClosest:
    case QueryKind::RayAll:
        answer.mHits = BruteForceRay(inSnapshot, inQuery.mRay);
        break;
    case QueryKind::ShapeAll:
    case QueryKind::ShapeClosest:
        answer.mHits = BruteForceShapeCast(inSnapshot, inQuery);
        break;
    case QueryKind::Sphere:
        answer.mBodies =
            BruteForceShape(inSnapshot, SphereShape(inQuery.mRadius), {inQuery.mCenter, Quat::Identity()});
        break;
    case QueryKind::Box:
        // WorldQuery's box: a flat one made a very thin one
        answer.mBodies =
            BruteForceShape(inSnapshot, BoxShape(inQuery.mBox.HalfExtent().cwiseMax(Vec3::Constant(1.0e-5f))),
                            {inQuery.mBox.Center(), Quat::Identity()});
        break;
    default:
        for (const PublishedPose& pose : inSnapshot.mPoses)
        {
            // A zero-length ray hits a solid shape exactly when it starts inside
            RayHit hit;
            hit.mFraction = 1.0f;
            if (pose.mShape->CastRay({pose.mTransform.InverseTransformPoint(inQuery.mCenter), Vec3::Zero()},
                                     hit))
                answer.mBodies.push_back(pose.mID);
        }
        std::sort(answer.mBodies.begin(), answer.mBodies.end());
        break;
    }
    return answer;
}

/// Whether the world's answer is the brute force's. CastRayClosest: the same fraction, and the hit of one of
/// the bodies the brute force hits at that fraction (several at once is a tie WorldQuery breaks its own way).
/// CastShapeClosest: see the file's comment.
bool Matches(const Query& inQuery, const Answer& inWorld, const Answer& inBruteForce)
{
    if (inQuery.mKind != QueryKind::RayClosest && inQuery.mKind != QueryKind::ShapeClosest)
        return SameAnswer(inWorld, inBruteForce);
    if (inBruteForce.mHits.empty()) return inWorld.mHits.empty();
    if (inWorld.mHits.size() != 1) return false;
    if (inQuery.mKind == QueryKind::ShapeClosest)
    {
        // The tolerance as a fraction of the displacement, twice: each side stops within it of the touch
        const float slack = 2.0f * QueryCastTolerance(inQuery.mRay.mOrigin) / inQuery.mRay.mDirection.norm();
        const RayCastResult& world = inWorld.mHits.front();
        if (world.mFraction > inBruteForce.mHits.front().mFraction + slack) return false;
        return std::any_of(inBruteForce.mHits.begin(), inBruteForce.mHits.end(),
                           [&](const RayCastResult& inHit) {
                               return inHit.mBody == world.mBody &&
                                      std::abs(inHit.mFraction - world.mFraction) <= slack;
                           });
    }
    for (const RayCastResult& hit : inBruteForce.mHits)
        if (hit.mFraction == inBruteForce.mHits.front().mFraction && SameHit(hit, inWorld.mHits.front()))
            return true;
    return false;
}

/// The step's job-system threads: 0 steps on the step thread alone.
class PublishedPoseQueryPropertyTest : public ::testing::TestWithParam<uint32_t>
{
};

TEST_P(PublishedPoseQueryPropertyTest, QueryDuringStepEqualsBruteForceOverLastPublishedState)
{
    std::unique_ptr<jobs::JobSystem> jobSystem;
    if (GetParam() > 0) jobSystem = std::make_unique<jobs::JobSystem>(jobs::JobSystem::Settings{GetParam()});
    PhysicsSettings settings;
    settings.mMaxBodies = 1024;
    settings.mUpdateBesideStepMinActiveBodies = 0; // With a job system, the rebuild runs beside the pairs
    const std::unique_ptr<PhysicsSystem> system = test::MakePhysicsSystem(settings);
    BodyInterface& bodies = system->GetBodyInterface();

    // Every body's id, and every shape held here too, so that the snapshots' raw shape pointers stay valid
    // whatever happens to the bodies
    std::vector<BodyID> ids;
    std::vector<ShapeRef> shapes;
    auto add = [&](const BodyCreationSettings& inSettings, Activation inActivation)
    {
        ids.push_back(bodies.CreateAndAddBody(inSettings, inActivation).Value());
        shapes.push_back(inSettings.mShape);
        return ids.back();
    };
    auto staticBox = [&](const Vec3& inCenter, const Vec3& inHalfExtent, const Quat& inRotation)
    {
        BodyCreationSettings body;
        body.mShape = BoxShape::Create(inHalfExtent).Value();
        body.mPosition = inCenter;
        body.mRotation = inRotation;
        body.mMotionType = MotionType::Static;
        body.mObjectLayer = Layers::cStatic;
        add(body, Activation::DontActivate);
    };

    // The statics: floor, walls, roof, a tilted slab, a block, a sphere and a bumpy triangle-mesh patch
    add(test::StaticFloorSettings(cHalfBox + 2.0f), Activation::DontActivate);
    const float wallHalfHeight = 0.5f * cRoofY + 0.5f;
    for (float side : {-1.0f, 1.0f})
    {
        staticBox(Vec3(side * (cHalfBox + 0.5f), wallHalfHeight, 0.0f),
                  Vec3(0.5f, wallHalfHeight, cHalfBox + 1.0f), Quat::Identity());
        staticBox(Vec3(0.0f, wallHalfHeight, side * (cHalfBox + 0.5f)),
                  Vec3(cHalfBox + 1.0f, wallHalfHeight, 0.5f), Quat::Identity());
    }
    staticBox(Vec3(0.0f, cRoofY + 0.5f, 0.0f), Vec3(cHalfBox + 1.0f, 0.5f, cHalfBox + 1.0f),
              Quat::Identity());
    staticBox(Vec3(-6.0f, 0.5f, -6.0f), Vec3(2.0f, 0.2f, 1.5f), Quat(Eigen::AngleAxisf(0.3f, Vec3::UnitZ())));
    staticBox(Vec3(6.0f, 0.5f, -6.0f), Vec3(0.8f, 0.5f, 0.8f), Quat(Eigen::AngleAxisf(0.6f, Vec3::UnitY())));
    {
        BodyCreationSettings body;
        body.mShape = SphereShape::Create(1.0f).Value();
        body.mPosition = Vec3(-6.0f, 0.0f, 6.0f);
        body.mMotionType = MotionType::Static;
        body.mObjectLayer = Layers::cStatic;
        add(body, Activation::DontActivate);
    }
    {
        std::mt19937 random(3);
        std::uniform_real_distribution<float> height(0.0f, 0.4f);
        std::vector<Vec3> vertices;
        std::vector<std::array<uint32_t, 3>> triangles;
        for (int z = 0; z <= 4; ++z)
            for (int x = 0; x <= 4; ++x)
                vertices.push_back(Vec3(float(x) * 1.2f, height(random), float(z) * 1.2f));
        for (uint32_t z = 0; z < 4; ++z)
            for (uint32_t x = 0; x < 4; ++x)
            {
                const uint32_t i = z * 5 + x;
                triangles.push_back({i, i + 5, i + 1});
                triangles.push_back({i + 1, i + 5, i + 6});
            }
        BodyCreationSettings body;
        body.mShape = TriangleMeshShape::Create(vertices, triangles).Value();
        body.mPosition = Vec3(3.5f, 0.01f, 3.5f);
        body.mMotionType = MotionType::Static;
        body.mObjectLayer = Layers::cStatic;
        add(body, Activation::DontActivate);
    }

    // The paddle that keeps the pile moving, driven by velocity
    {
        BodyCreationSettings paddle;
        paddle.mShape = BoxShape::Create(Vec3(3.0f, 0.3f, 0.25f)).Value();
        paddle.mPosition = Vec3(0.0f, 0.35f, 0.0f);
        paddle.mMotionType = MotionType::Kinematic;
        const BodyID id = add(paddle, Activation::Activate);
        ASSERT_TRUE(bodies.SetAngularVelocity(id, Vec3(0.0f, 1.2f, 0.0f)));
    }

    // The moving bodies, on a grid above the statics, tilted so they tumble; sleeping off so every step
    // publishes them
    const size_t firstDynamic = ids.size();
    {
        std::mt19937 random(4);
        std::uniform_real_distribution<float> unit(0.0f, 1.0f);
        const ShapeRef dumbbellBall = SphereShape::Create(0.2f).Value();
        for (int i = 0; i < 90; ++i)
        {
            BodyCreationSettings body;
            body.mPosition = Vec3(-7.0f + 1.75f * float(i % 9), 2.1f + 1.4f * float(i / 45),
                                  -7.0f + 3.5f * float((i / 9) % 5));
            body.mRotation = test::published_pose_stress::RandomRotation(random);
            body.mAllowSleeping = false;
            switch (i % 4)
            {
            case 0:
                body.mShape = SphereShape::Create(0.2f + 0.3f * unit(random)).Value();
                break;
            case 1:
                body.mShape =
                    CapsuleShape::Create(0.2f + 0.2f * unit(random), 0.15f + 0.15f * unit(random)).Value();
                break;
            case 2:
                body.mShape =
                    CompoundShape::Create({{dumbbellBall, {Vec3(-0.35f, 0.0f, 0.0f), Quat::Identity()}},
                                           {dumbbellBall, {Vec3(0.35f, 0.0f, 0.0f), Quat::Identity()}},
                                           {BoxShape::Create(Vec3(0.3f, 0.06f, 0.06f)).Value(), {}}})
                        .Value();
                break;
            default:
                body.mShape = BoxShape::Create(Vec3(0.15f + 0.3f * unit(random), 0.15f + 0.3f * unit(random),
                                                    0.15f + 0.3f * unit(random)))
                                  .Value();
                break;
            }
            add(body, Activation::Activate);
        }
    }
    ASSERT_TRUE(system->Update(1.0f / 60.0f)); // Every body published by a step once before the run

    // Relaxed for the stop flag and the counters; the snapshot goes through latestMutex
    std::atomic<bool> stop{false};
    std::atomic<bool> stepping{false}; // Seq-cst: read around each query, the plainest to reason about
    std::atomic<uint64_t> updates{0}, failedCalls{0}, unreadable{0};
    std::mutex latestMutex; // Guards latest
    std::shared_ptr<const Snapshot> latest;
    const BodyManager& manager = system->GetBodyManager();

    auto capture = [&](uint64_t inGeneration)
    {
        auto snapshot = std::make_shared<Snapshot>();
        snapshot->mGeneration = inGeneration;
        snapshot->mPoses.resize(ids.size());
        const PoseReader reader(manager);
        for (size_t i = 0; i < ids.size(); ++i)
            if (!reader.Read(ids[i], snapshot->mPoses[i])) unreadable.fetch_add(1, std::memory_order_relaxed);
        const std::lock_guard lock(latestMutex);
        latest = std::move(snapshot);
    };
    capture(0);

    std::thread stepThread(
        [&]
        {
            uint64_t generation = 0, failed = 0;
            while (!stop.load(std::memory_order_relaxed))
            {
                stepping.store(true);
                const Status status =
                    jobSystem ? system->Update(1.0f / 60.0f, 1, *jobSystem) : system->Update(1.0f / 60.0f);
                stepping.store(false);
                failed += status ? 0 : 1;
                capture(++generation); // Nothing publishes until the next Update: this is the world's state
                updates.store(generation, std::memory_order_relaxed);
            }
            failedCalls.fetch_add(failed, std::memory_order_relaxed);
        });

    struct Counts
    {
        uint64_t mDuringStep[int(QueryKind::Count)] = {};
        uint64_t mBetweenSteps = 0; ///< Conclusive, but the step was not running at either end
        uint64_t mNonEmpty = 0;     ///< Conclusive comparisons with at least one body in the answer
        uint64_t mMismatches = 0;
        uint64_t mStale = 0;          ///< The snapshot went stale during the query: not compared
        uint64_t mStaleDiffering = 0; ///< Of those, answers that differ from the stale snapshot's
        uint64_t DuringStep() const
        {
            uint64_t sum = 0;
            for (uint64_t count : mDuringStep)
                sum += count;
            return sum;
        }
    };
    std::mutex resultMutex; // Guards total and failures
    Counts total;
    std::vector<std::string> failures;
    std::atomic<uint64_t> duringStepSoFar{0};

    auto queryThread = [&](uint32_t inSeed)
    {
        const WorldQuery& world = system->GetWorldQuery();
        std::mt19937 random(inSeed);
        std::uniform_int_distribution<int> kind(0, int(QueryKind::Count) - 1);
        std::uniform_int_distribution<size_t> pickDynamic(firstDynamic, ids.size() - 1);
        std::uniform_real_distribution<float> unit(0.0f, 1.0f), symmetric(-1.0f, 1.0f),
            x(-cHalfBox, cHalfBox), y(0.0f, cRoofY);
        Counts counts;
        std::vector<std::string> found;
        Answer answer;
        uint64_t failed = 0;
        while (!stop.load(std::memory_order_relaxed))
        {
            std::shared_ptr<const Snapshot> snapshot;
            {
                const std::lock_guard lock(latestMutex);
                snapshot = latest;
            }
            // Half the queries aim at a moving body's published pose, so that many answers are not empty
            const Vec3 jitter(symmetric(random), symmetric(random), symmetric(random));
            const Vec3 focus =
                unit(random) < 0.5f
                    ? snapshot->mPoses[pickDynamic(random)].mTransform.mPosition + 0.3f * jitter
                    : Vec3(x(random), y(random), x(random));
            Query query;
            query.mKind = QueryKind(kind(random));
            switch (query.mKind)
            {
            case QueryKind::RayClosest:
            case QueryKind::RayAll:
            case QueryKind::ShapeAll:
            case QueryKind::ShapeClosest:
            {
                query.mRotation = test::published_pose_stress::RandomRotation(random);
                Vec3 away(symmetric(random), symmetric(random), symmetric(random));
                if (away.squaredNorm() < 1.0e-4f) away = Vec3::UnitY();
                query.mRay.mOrigin = focus + (1.0f + 7.0f * unit(random)) * away.normalized();
                query.mRay.mDirection = (focus - query.mRay.mOrigin) * (1.0f + 1.5f * unit(random));
                break;
            }
            case QueryKind::Sphere:
                query.mCenter = focus;
                query.mRadius = 0.05f + 2.0f * unit(random);
                break;
            case QueryKind::Box:
            {
                const Vec3 halfExtent(0.02f + 2.0f * unit(random), 0.02f + 2.0f * unit(random),
                                      0.02f + 2.0f * unit(random));
                query.mBox = AABB(focus - halfExtent, focus + halfExtent);
                break;
            }
            default:
                query.mCenter = focus;
                break;
            }

            const bool steppingAtStart = stepping.load();
            const bool ok = RunWorldQuery(world, query, answer);
            const bool steppingAtEnd = stepping.load();
            failed += ok ? 0 : 1;

            // Nothing published since the capture: every version as the snapshot has it
            bool unchanged = true;
            {
                const PoseReader reader(manager);
                PublishedPose pose;
                for (size_t i = 0; i < ids.size() && unchanged; ++i)
                    unchanged = reader.Read(ids[i], pose) && pose.mVersion == snapshot->mPoses[i].mVersion;
            }
            const Answer expected = BruteForce(*snapshot, query);
            const bool matches = Matches(query, answer, expected);
            if (!unchanged)
            {
                ++counts.mStale;
                counts.mStaleDiffering += matches ? 0 : 1;
                continue;
            }
            if (steppingAtStart || steppingAtEnd)
            {
                ++counts.mDuringStep[int(query.mKind)];
                if ((counts.DuringStep() & 63) == 0) duringStepSoFar.fetch_add(64, std::memory_order_relaxed);
            }
            else
                ++counts.mBetweenSteps;
            counts.mNonEmpty += expected.mBodies.empty() && expected.mHits.empty() ? 0 : 1;
            if (matches) continue;
            ++counts.mMismatches;
            if (found.size() < 5)
            {
                std::string text = Describe(query) + " on snapshot " + std::to_string(snapshot->mGeneration) +
                                   " (step running at start/end " + std::to_string(steppingAtStart) + "/" +
                                   std::to_string(steppingAtEnd) + "): the world answered " +
                                   Describe(answer) + ", the brute force " + Describe(expected);
                for (const PublishedPose& pose : snapshot->mPoses)
                {
                    const auto in = [&](const Answer& inAnswer)
                    {
                        return std::find(inAnswer.mBodies.begin(), inAnswer.mBodies.end(), pose.mID) !=
                                   inAnswer.mBodies.end() ||
                               std::any_of(inAnswer.mHits.begin(), inAnswer.mHits.end(),
                                           [&](const RayCastResult& inHit)
                                           { return inHit.mBody == pose.mID; });
                    };
                    if (in(answer) != in(expected))
                        text += "; body " + std::to_string(pose.mID.GetIndex()) + " at " +
                                Describe(pose.mTransform.mPosition) + " version " +
                                std::to_string(pose.mVersion);
                }
                found.push_back(std::move(text));
            }
        }
        const std::lock_guard lock(resultMutex);
        for (int k = 0; k < int(QueryKind::Count); ++k)
            total.mDuringStep[k] += counts.mDuringStep[k];
        total.mBetweenSteps += counts.mBetweenSteps;
        total.mNonEmpty += counts.mNonEmpty;
        total.mMismatches += counts.mMismatches;
        total.mStale += counts.mStale;
        total.mStaleDiffering += counts.mStaleDiffering;
        for (std::string& text : found)
            failures.push_back(std::move(text));
        failedCalls.fetch_add(failed, std::memory_order_relaxed);
    };

    // Until the target of comparisons during a step is reached (and at least a second and 100 updates have
    // passed), or the time cap: under ThreadSanitizer the brute force is slow, and the floor below is lower
    const uint64_t target = 5000;
    const uint64_t required = test::cSlowBuild ? 200 : 2000;
    const auto start = std::chrono::steady_clock::now();
    std::thread queries[2] = {std::thread(queryThread, 11u), std::thread(queryThread, 12u)};
    for (;;)
    {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        const auto elapsed = std::chrono::steady_clock::now() - start;
        if (elapsed >= std::chrono::seconds(20)) break;
        if (elapsed >= std::chrono::seconds(1) && duringStepSoFar.load(std::memory_order_relaxed) >= target &&
            updates.load(std::memory_order_relaxed) >= 100)
            break;
    }
    stop.store(true, std::memory_order_relaxed);
    stepThread.join();
    for (std::thread& thread : queries)
        thread.join();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    const uint64_t duringStep = total.DuringStep();
    const uint64_t conclusive = duringStep + total.mBetweenSteps;
    std::printf(
        "[ figure   ] %llu comparisons during a step (ray closest %llu, ray all %llu, sphere %llu, box %llu, "
        "point %llu, shape cast all %llu, shape cast closest %llu), %llu between steps, %llu mismatches; "
        "%llu of %llu answers not "
        "empty; %llu queries on a "
        "snapshot gone stale, %llu of them differing from it; %llu updates in %.1f s\n",
        (unsigned long long)duringStep, (unsigned long long)total.mDuringStep[0],
        (unsigned long long)total.mDuringStep[1], (unsigned long long)total.mDuringStep[2],
        (unsigned long long)total.mDuringStep[3], (unsigned long long)total.mDuringStep[4],
        (unsigned long long)total.mDuringStep[5], (unsigned long long)total.mDuringStep[6],
        (unsigned long long)total.mBetweenSteps, (unsigned long long)total.mMismatches,
        (unsigned long long)total.mNonEmpty, (unsigned long long)conclusive, (unsigned long long)total.mStale,
        (unsigned long long)total.mStaleDiffering, (unsigned long long)updates.load(), seconds);
    for (const std::string& failure : failures)
        ADD_FAILURE() << failure;
    EXPECT_EQ(total.mMismatches, 0u);
    EXPECT_EQ(failedCalls.load(), 0u);
    EXPECT_EQ(unreadable.load(), 0u) << "a body's published pose could not be read for a snapshot";
    EXPECT_GE(duringStep, required);
    for (int k = 0; k < int(QueryKind::Count); ++k)
        EXPECT_GT(total.mDuringStep[k], 0u) << KindName(QueryKind(k)) << " was never compared during a step";
    // The comparisons compared something: a good share of the answers name bodies
    EXPECT_GE(total.mNonEmpty * 4, conclusive);
}

INSTANTIATE_TEST_SUITE_P(Steps, PublishedPoseQueryPropertyTest, ::testing::Values(0u, 2u),
                         [](const auto& inInfo) {
                             return inInfo.param == 0 ? std::string("NoJobSystem")
                                                      : std::to_string(inInfo.param) + "JobThreads";
                         });

} // namespace
} // namespace cairn
