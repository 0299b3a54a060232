#include "narrowphase/ShapeCast.h"

#include "cairn/physics/narrowphase/CollideShapes.h"

#include <algorithm>
#include <limits>

namespace cairn::physics
{

namespace
{
/// Halvings of an overshot advance: enough to narrow any fraction interval to a float step of it.
constexpr int cMaxBisections = 24;

/// A manifold's point nearest the allowed depth, with its gap to that depth (< 0: sunk past it).
struct Nearest
{
    float mGap = std::numeric_limits<float>::max();
    ShapeCastHit mHit;
};

/// What A at one fraction finds of B.
struct Probe
{
    Nearest mLeast;                ///< Over every manifold
    Nearest mTouch;                ///< Over the manifolds A approaches
    std::optional<float> mAdvance; ///< The advance (fraction) their planes allow, when A approaches any
    ShapeCastHit mLimiting;        ///< The manifold that limits it
};

class Caster
{
public:
    Caster(const Shape& inShapeA, const Transform& inStartA, const Vec3& inDisplacement,
           const Shape& inShapeB, const Transform& inTransformB, const ShapeCastSettings& inSettings)
        : mShapeA(inShapeA), mStartA(inStartA), mDisplacement(inDisplacement), mShapeB(inShapeB),
          mTransformB(inTransformB), mSettings(inSettings), mLength(inDisplacement.norm())
    {
    }

    std::optional<ShapeCastHit> Run() const
    {
        float t = 0.0f;
        float lastClear = 0.0f; // The last fraction found clear of B
        const Probe start = At(0.0f);
        // Clear of B at the start: any depth past the allowed one later means an advance crossed B's surface
        const bool startsClear = start.mLeast.mGap >= 0.0f;
        for (int iteration = 0;; ++iteration)
        {
            const Probe probe = iteration == 0 ? start : At(t);
            if (iteration > 0 && IsPast(probe, startsClear))
                return Bisect(lastClear, t, startsClear ? probe.mLeast.mHit : probe.mTouch.mHit, startsClear);
            if (IsTouching(probe)) return probe.mTouch.mHit;
            if (!probe.mAdvance.has_value()) return std::nullopt; // Nothing it approaches within reach
            // Out of advances: it stops here, clear of B, with the manifold nearest
            if (iteration >= mSettings.mMaxIterations) return probe.mLimiting;
            lastClear = t;
            t += std::max(*probe.mAdvance, 0.0f);
            if (t >= mSettings.mMaxFraction) return std::nullopt;
        }
    }

private:
    Probe At(float inT) const
    {
        Transform at = mStartA;
        at.mPosition += inT * mDisplacement;
        CollideSettings collide;
        collide.mFaceNormalsAtInternalEdges = false; // See there: the plane's depth beside a triangle is none
        collide.mSweep = (mSettings.mMaxFraction - inT) * mDisplacement;
        const float allowed = mSettings.mAllowedPenetration;
        const float tolerance = mSettings.mTolerance;
        collide.mMaxSeparation =
            std::max((mSettings.mMaxFraction - inT) * mLength + tolerance - allowed, 0.0f);
        Probe probe;
        CollideShapes(mShapeA, at, mShapeB, mTransformB, collide,
                      [&](const ContactManifold& inManifold)
                      {
                          Nearest nearest;
                          for (int i = 0; i < inManifold.mNumPoints; ++i)
                              if (const float gap = allowed - inManifold.mPoints[i].mPenetration;
                                  gap < nearest.mGap)
                              {
                                  nearest.mGap = gap;
                                  nearest.mHit = {inT, inManifold, i};
                              }
                          if (nearest.mGap < probe.mLeast.mGap) probe.mLeast = nearest;
                          const float approach = mDisplacement.dot(inManifold.mNormal);
                          // Parallel or moving away cannot stop it (a zero displacement approaches nothing
                          // and is stopped by what it touches)
                          const bool approaches = approach > 1.0e-6f * mLength;
                          if (!approaches && mLength != 0.0f) return;
                          if (nearest.mGap < probe.mTouch.mGap) probe.mTouch = nearest;
                          if (!approaches) return;
                          // Aim for half the tolerance: the next gap is then within it, never below zero
                          const float step = (nearest.mGap - 0.5f * tolerance) / approach;
                          if (!probe.mAdvance.has_value() || step < *probe.mAdvance)
                          {
                              probe.mAdvance = step;
                              probe.mLimiting = nearest.mHit;
                          }
                      });
        return probe;
    }

    bool IsTouching(const Probe& inProbe) const { return inProbe.mTouch.mGap <= mSettings.mTolerance; }

    /// Sunk past the allowed depth: into anything when A started clear of B, else into what it approaches.
    static bool IsPast(const Probe& inProbe, bool inStartsClear)
    {
        return (inStartsClear ? inProbe.mLeast.mGap : inProbe.mTouch.mGap) < 0.0f;
    }

    /// Each manifold's points bound the gap along its normal only as well as the pair's routine makes them
    /// (a box's clipped face points can lie farther than the corner nearest the other box), so an advance
    /// can go past the surface. Between inClear (clear of B) and inPast (past the allowed depth): the touch,
    /// or the last fraction found clear, with the manifold met just past it.
    ShapeCastHit Bisect(float inClear, float inPast, ShapeCastHit inPastHit, bool inStartsClear) const
    {
        for (int i = 0; i < cMaxBisections; ++i)
        {
            const float middle = 0.5f * (inClear + inPast);
            if (middle <= inClear || middle >= inPast) break; // A float step apart
            const Probe probe = At(middle);
            if (IsPast(probe, inStartsClear))
            {
                inPast = middle;
                inPastHit = inStartsClear ? probe.mLeast.mHit : probe.mTouch.mHit;
            }
            else if (IsTouching(probe))
                return probe.mTouch.mHit;
            else
                inClear = middle;
        }
        inPastHit.mFraction = inClear;
        return inPastHit;
    }

    const Shape& mShapeA;
    const Transform& mStartA;
    const Vec3& mDisplacement;
    const Shape& mShapeB;
    const Transform& mTransformB;
    const ShapeCastSettings& mSettings;
    const float mLength;
};
} // namespace

std::optional<ShapeCastHit> CastShapeAgainst(const Shape& inShapeA, const Transform& inStartA,
                                             const Vec3& inDisplacement, const Shape& inShapeB,
                                             const Transform& inTransformB,
                                             const ShapeCastSettings& inSettings)
{
    return Caster(inShapeA, inStartA, inDisplacement, inShapeB, inTransformB, inSettings).Run();
}

} // namespace cairn::physics
