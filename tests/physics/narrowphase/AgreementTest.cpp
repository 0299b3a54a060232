// Each dedicated pair routine against the generic GJK/EPA answer on random overlapping configurations.

#include "common/ShapeExpect.h"
#include "narrowphase/CollideBoxBox.h"
#include "narrowphase/CollideCapsuleCapsule.h"
#include "narrowphase/CollideSphereBox.h"
#include "narrowphase/CollideSphereCapsule.h"
#include "narrowphase/CollideSphereSphere.h"
#include "narrowphase/ConvexContact.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{
using cairn::test::MaxPenetration;

constexpr int cNumCases = 10000;
constexpr float cNormalDotTolerance = 1.0e-2f; // 1 - dot(dedicated, GJK/EPA)
constexpr float cDepthAbsTolerance = 1.0e-3f;
constexpr float cDepthRelTolerance = 1.0e-2f;
constexpr float cAmbiguityGap = 1.0e-3f; // Second-best answer this close to the best: the normal is ambiguous

class Random
{
public:
    explicit Random(uint32_t inSeed) : mEngine(inSeed) {}
    float Uniform(float inMin, float inMax)
    {
        return std::uniform_real_distribution<float>(inMin, inMax)(mEngine);
    }
    Vec3 InBox(float inHalf)
    {
        return {Uniform(-inHalf, inHalf), Uniform(-inHalf, inHalf), Uniform(-inHalf, inHalf)};
    }
    Quat Rotation()
    {
        std::normal_distribution<float> n;
        Quat q(n(mEngine), n(mEngine), n(mEngine), n(mEngine));
        return q.normalized();
    }

private:
    std::mt19937 mEngine;
};

// Counts of one agreement run
struct Tally
{
    int mCompared = 0;
    int mSkipped = 0;
    int mNormalMismatches = 0;
    int mDepthMismatches = 0;
    int mMissing = 0;             ///< GJK/EPA found an overlap, the dedicated routine nothing
    int mReferenceUnreliable = 0; ///< EPA's depth is not the overlap along its own normal: no oracle there
    std::string mFirstMismatch;
};

void Compare(const ContactManifold& inDedicated, bool inHit, const ConvexContact& inReference, Tally& ioTally)
{
    ++ioTally.mCompared;
    if (!inHit || inDedicated.mNumPoints == 0)
    {
        ++ioTally.mMissing;
        return;
    }
    const bool normalOff = 1.0f - inDedicated.mNormal.dot(inReference.mNormal) > cNormalDotTolerance;
    const float depth = MaxPenetration(inDedicated);
    const float tol = std::max(cDepthAbsTolerance, cDepthRelTolerance * std::abs(inReference.mPenetration));
    const bool depthOff = std::abs(depth - inReference.mPenetration) > tol;
    ioTally.mNormalMismatches += normalOff ? 1 : 0;
    ioTally.mDepthMismatches += depthOff ? 1 : 0;
    if ((depthOff || normalOff) && ioTally.mFirstMismatch.empty())
    {
        std::ostringstream out;
        out << "dedicated normal (" << inDedicated.mNormal.transpose() << ") depth " << depth
            << ", GJK/EPA normal (" << inReference.mNormal.transpose() << ") depth "
            << inReference.mPenetration;
        ioTally.mFirstMismatch = out.str();
    }
}

void ExpectAgreement(const Tally& inTally)
{
    EXPECT_EQ(inTally.mCompared + inTally.mSkipped + inTally.mReferenceUnreliable, cNumCases);
    EXPECT_EQ(inTally.mMissing, 0);
    EXPECT_EQ(inTally.mNormalMismatches, 0) << inTally.mFirstMismatch;
    EXPECT_EQ(inTally.mDepthMismatches, 0) << inTally.mFirstMismatch;
    // The exclusion rules must stay exceptions, not a way to hide disagreement
    EXPECT_LT(inTally.mSkipped, cNumCases / 50);
    EXPECT_LT(inTally.mReferenceUnreliable, cNumCases / 200);
    std::printf("compared %d, skipped %d as ambiguous, %d where EPA's answer contradicts itself\n",
                inTally.mCompared, inTally.mSkipped, inTally.mReferenceUnreliable);
}

// Finds a random overlapping configuration: GJK/EPA reports penetration > 1 mm
template <class MakeCase> void RunCases(uint32_t inSeed, MakeCase inMakeCase)
{
    Random rng(inSeed);
    Tally tally;
    int done = 0;
    while (done < cNumCases)
    {
        if (inMakeCase(rng, tally)) ++done;
    }
    ExpectAgreement(tally);
}

enum class Reference
{
    NotACase,   ///< No overlap of at least 1 mm
    Unreliable, ///< Counted in the tally: EPA stopped where its depth is not the overlap along its normal
    Ok,
};

/// GJK/EPA's answer for the pair. EPA's answer is checked against the exact overlap of the two shapes along
/// its own normal (their supports): on a curved shape EPA can stop early with a depth and a normal that do
/// not belong together (seen once in 10,000 sphere-box cases with Clang's arithmetic: depth 0.846 reported,
/// 0.858 along its normal, the true minimum 0.8525), and then it is no oracle.
Reference ReferenceContact(const ConvexShape& inA, const Transform& inTransformA, const ConvexShape& inB,
                           const Transform& inTransformB, ConvexContact& outReference, Tally& ioTally)
{
    const ConvexSupport a = ConvexSupport::FromShape(inA, inTransformA);
    const ConvexSupport b = ConvexSupport::FromShape(inB, inTransformB);
    if (!FindConvexContact(a, b, 0.0f, outReference) || outReference.mPenetration < 1.0e-3f)
        return Reference::NotACase;
    const Vec3& n = outReference.mNormal; // From A towards B
    const float overlap =
        (a.GetSupport(n, a.GetRadius()) - b.GetSupport(-n, b.GetRadius())).dot(n) / n.norm();
    const float tolerance = std::max(cDepthAbsTolerance, cDepthRelTolerance * std::abs(overlap));
    if (std::abs(overlap - outReference.mPenetration) > tolerance)
    {
        ++ioTally.mReferenceUnreliable;
        return Reference::Unreliable;
    }
    return Reference::Ok;
}

TEST(AgreementTest, SphereSphere)
{
    const CollideSettings settings;
    RunCases(1,
             [&](Random& ioRng, Tally& ioTally)
             {
                 const auto a = SphereShape::Create(ioRng.Uniform(0.05f, 2.0f)).Value();
                 const auto b = SphereShape::Create(ioRng.Uniform(0.05f, 2.0f)).Value();
                 const Transform ta{ioRng.InBox(1.0f), ioRng.Rotation()};
                 const Transform tb{ioRng.InBox(1.0f), ioRng.Rotation()};
                 ConvexContact ref;
                 if (const Reference use = ReferenceContact(*a, ta, *b, tb, ref, ioTally);
                     use != Reference::Ok)
                     return use == Reference::Unreliable;
                 ContactManifold m;
                 const bool hit = CollideSphereSphere(*a, ta, *b, tb, settings, m);
                 Compare(m, hit, ref, ioTally);
                 return true;
             });
}

TEST(AgreementTest, SphereBox)
{
    const CollideSettings settings;
    RunCases(2,
             [&](Random& ioRng, Tally& ioTally)
             {
                 const auto a = SphereShape::Create(ioRng.Uniform(0.05f, 1.0f)).Value();
                 const Vec3 extent(ioRng.Uniform(0.05f, 1.5f), ioRng.Uniform(0.05f, 1.5f),
                                   ioRng.Uniform(0.05f, 1.5f));
                 const auto b = BoxShape::Create(extent).Value();
                 const Transform ta{ioRng.InBox(1.5f), ioRng.Rotation()};
                 const Transform tb{ioRng.InBox(1.5f), ioRng.Rotation()};
                 ConvexContact ref;
                 if (const Reference use = ReferenceContact(*a, ta, *b, tb, ref, ioTally);
                     use != Reference::Ok)
                     return use == Reference::Unreliable;
                 // Centre inside the box with two faces at nearly the same distance: either face is right
                 const Vec3 local = tb.InverseTransformPoint(ta.mPosition);
                 if ((local.cwiseAbs().array() < extent.array()).all())
                 {
                     Vec3 toFace = extent - local.cwiseAbs();
                     std::sort(toFace.data(), toFace.data() + 3);
                     if (toFace[1] - toFace[0] < cAmbiguityGap)
                     {
                         ++ioTally.mSkipped;
                         return true;
                     }
                 }
                 ContactManifold m;
                 const bool hit = CollideSphereBox(*a, ta, *b, tb, settings, m);
                 Compare(m, hit, ref, ioTally);
                 return true;
             });
}

TEST(AgreementTest, SphereCapsule)
{
    const CollideSettings settings;
    RunCases(3,
             [&](Random& ioRng, Tally& ioTally)
             {
                 const auto a = SphereShape::Create(ioRng.Uniform(0.05f, 1.0f)).Value();
                 const auto b =
                     CapsuleShape::Create(ioRng.Uniform(0.0f, 1.5f), ioRng.Uniform(0.05f, 1.0f)).Value();
                 const Transform ta{ioRng.InBox(1.5f), ioRng.Rotation()};
                 const Transform tb{ioRng.InBox(1.5f), ioRng.Rotation()};
                 ConvexContact ref;
                 if (const Reference use = ReferenceContact(*a, ta, *b, tb, ref, ioTally);
                     use != Reference::Ok)
                     return use == Reference::Unreliable;
                 ContactManifold m;
                 const bool hit = CollideSphereCapsule(*a, ta, *b, tb, settings, m);
                 Compare(m, hit, ref, ioTally);
                 return true;
             });
}

TEST(AgreementTest, CapsuleCapsule)
{
    const CollideSettings settings;
    RunCases(4,
             [&](Random& ioRng, Tally& ioTally)
             {
                 const auto a =
                     CapsuleShape::Create(ioRng.Uniform(0.0f, 1.5f), ioRng.Uniform(0.05f, 1.0f)).Value();
                 const auto b =
                     CapsuleShape::Create(ioRng.Uniform(0.0f, 1.5f), ioRng.Uniform(0.05f, 1.0f)).Value();
                 const Transform ta{ioRng.InBox(1.5f), ioRng.Rotation()};
                 const Transform tb{ioRng.InBox(1.5f), ioRng.Rotation()};
                 ConvexContact ref;
                 if (const Reference use = ReferenceContact(*a, ta, *b, tb, ref, ioTally);
                     use != Reference::Ok)
                     return use == Reference::Unreliable;
                 ContactManifold m;
                 const bool hit = CollideCapsuleCapsule(*a, ta, *b, tb, settings, m);
                 Compare(m, hit, ref, ioTally);
                 return true;
             });
}

// Penetration along every one of the 15 separating axis candidates of two boxes, computed from scratch
std::vector<std::pair<float, Vec3>> BoxAxisPenetrations(const Vec3& inExtentA, const Transform& inA,
                                                        const Vec3& inExtentB, const Transform& inB)
{
    const Mat3 ra = inA.mRotation.toRotationMatrix();
    const Mat3 rb = inB.mRotation.toRotationMatrix();
    std::vector<Vec3> axes;
    for (int i = 0; i < 3; ++i)
    {
        axes.push_back(ra.col(i));
        axes.push_back(rb.col(i));
        for (int j = 0; j < 3; ++j)
        {
            const Vec3 c = ra.col(i).cross(rb.col(j));
            if (c.norm() > 1.0e-3f) axes.push_back(c.normalized());
        }
    }
    std::vector<std::pair<float, Vec3>> result;
    const Vec3 d = inB.mPosition - inA.mPosition;
    for (const Vec3& axis : axes)
    {
        const float projA = (ra.transpose() * axis).cwiseAbs().dot(inExtentA);
        const float projB = (rb.transpose() * axis).cwiseAbs().dot(inExtentB);
        result.emplace_back(projA + projB - std::abs(axis.dot(d)), axis);
    }
    std::sort(result.begin(), result.end(),
              [](const auto& inL, const auto& inR) { return inL.first < inR.first; });
    return result;
}

TEST(AgreementTest, BoxBox)
{
    const CollideSettings settings;
    int edgeAxes = 0;
    RunCases(
        5,
        [&](Random& ioRng, Tally& ioTally)
        {
            const Vec3 ea(ioRng.Uniform(0.05f, 1.5f), ioRng.Uniform(0.05f, 1.5f), ioRng.Uniform(0.05f, 1.5f));
            const Vec3 eb(ioRng.Uniform(0.05f, 1.5f), ioRng.Uniform(0.05f, 1.5f), ioRng.Uniform(0.05f, 1.5f));
            const auto a = BoxShape::Create(ea).Value();
            const auto b = BoxShape::Create(eb).Value();
            const Transform ta{ioRng.InBox(1.5f), ioRng.Rotation()};
            const Transform tb{ioRng.InBox(1.5f), ioRng.Rotation()};
            ConvexContact ref;
            if (const Reference use = ReferenceContact(*a, ta, *b, tb, ref, ioTally); use != Reference::Ok)
                return use == Reference::Unreliable;
            // Two different axes with nearly the same penetration: both answers are right
            const auto axes = BoxAxisPenetrations(ea, ta, eb, tb);
            for (size_t i = 1; i < axes.size() && axes[i].first - axes[0].first < cAmbiguityGap; ++i)
                if (std::abs(axes[i].second.dot(axes[0].second)) < 0.999f)
                {
                    ++ioTally.mSkipped;
                    return true;
                }
            ContactManifold m;
            BoxBoxAxis axis = BoxBoxAxis::FaceA;
            const bool hit = CollideBoxBox(*a, ta, *b, tb, settings, m, &axis);
            edgeAxes += axis == BoxBoxAxis::Edge ? 1 : 0;
            Compare(m, hit, ref, ioTally);
            return true;
        });
    // The random set must exercise the edge-edge branch too, not only face clipping
    EXPECT_GT(edgeAxes, cNumCases / 100);
    std::printf("edge-edge axis in %d cases\n", edgeAxes);
}

} // namespace
} // namespace cairn
