#include "narrowphase/Gjk.h"

#include "narrowphase/ClosestPoints.h"

#include <algorithm>

namespace cairn::physics
{

namespace
{

// Replaces the simplex by the smallest sub-simplex that holds the point closest to the origin, and returns
// that point and its barycentric weights (in outWeights, over the reduced simplex). Returns false when the
// origin is inside the tetrahedron.
bool ReduceSimplex(GjkSimplex& ioSimplex, float outWeights[4], Vec3& outClosest)
{
    GjkSimplex& s = ioSimplex;
    // inIndices is ascending, so compacting in place never overwrites an entry still to be read
    const auto keep = [&s](const int* inIndices, int inCount)
    {
        for (int i = 0; i < inCount; ++i)
        {
            s.mY[i] = s.mY[inIndices[i]];
            s.mA[i] = s.mA[inIndices[i]];
            s.mB[i] = s.mB[inIndices[i]];
        }
        s.mCount = inCount;
    };
    const Vec3 origin = Vec3::Zero();

    switch (s.mCount)
    {
    case 1:
        outWeights[0] = 1.0f;
        outClosest = s.mY[0];
        return true;
    case 2:
    {
        float t;
        outClosest = ClosestPointOnSegment(origin, s.mY[0], s.mY[1], t);
        if (t <= 0.0f || t >= 1.0f)
        {
            const int idx[1] = {t <= 0.0f ? 0 : 1};
            keep(idx, 1);
            outWeights[0] = 1.0f;
        }
        else
        {
            outWeights[0] = 1.0f - t;
            outWeights[1] = t;
        }
        return true;
    }
    case 3:
    {
        Vec3 bary;
        uint32_t feature;
        outClosest = ClosestPointOnTriangle(origin, s.mY[0], s.mY[1], s.mY[2], bary, feature);
        int idx[3];
        int n = 0;
        for (int i = 0; i < 3; ++i)
            if (feature & (1u << i))
            {
                outWeights[n] = bary[i];
                idx[n++] = i;
            }
        if (n < 3) keep(idx, n);
        return true;
    }
    default:
    {
        // Tetrahedron: test the origin against each face plane, oriented away from the opposite vertex
        static constexpr int cFaces[4][4] = {{0, 1, 2, 3}, {0, 3, 1, 2}, {0, 2, 3, 1}, {1, 3, 2, 0}};
        bool outsideAny = false;
        float bestSq = cLargeFloat;
        GjkSimplex bestSimplex;
        float bestWeights[3] = {1.0f, 0.0f, 0.0f};
        Vec3 best = s.mY[0];
        for (const auto& f : cFaces)
        {
            const Vec3& a = s.mY[f[0]];
            const Vec3 n = (s.mY[f[1]] - a).cross(s.mY[f[2]] - a);
            const float signOrigin = -n.dot(a);
            const float signOpposite = n.dot(s.mY[f[3]] - a);
            // A flat tetrahedron (signOpposite ~ 0) cannot contain the origin: treat every face as a
            // candidate
            const bool outside = signOrigin * signOpposite < 0.0f ||
                                 std::abs(signOpposite) <= 1.0e-7f * n.norm() * (1.0f + a.norm());
            if (!outside) continue;
            outsideAny = true;
            GjkSimplex tri;
            tri.mCount = 3;
            for (int i = 0; i < 3; ++i)
            {
                tri.mY[i] = s.mY[f[i]];
                tri.mA[i] = s.mA[f[i]];
                tri.mB[i] = s.mB[f[i]];
            }
            float w[4];
            Vec3 p;
            ReduceSimplex(tri, w, p);
            if (p.squaredNorm() < bestSq)
            {
                bestSq = p.squaredNorm();
                best = p;
                bestSimplex.mCount = tri.mCount;
                for (int i = 0; i < tri.mCount; ++i)
                {
                    bestSimplex.mY[i] = tri.mY[i];
                    bestSimplex.mA[i] = tri.mA[i];
                    bestSimplex.mB[i] = tri.mB[i];
                    bestWeights[i] = w[i];
                }
            }
        }
        if (!outsideAny)
        {
            outClosest = Vec3::Zero();
            return false;
        }
        s.mCount = bestSimplex.mCount;
        for (int i = 0; i < s.mCount; ++i)
        {
            s.mY[i] = bestSimplex.mY[i];
            s.mA[i] = bestSimplex.mA[i];
            s.mB[i] = bestSimplex.mB[i];
            outWeights[i] = bestWeights[i];
        }
        outClosest = best;
        return true;
    }
    }
}

} // namespace

GjkResult Gjk::ClosestPoints(const ConvexSupport& inA, float inInflationA, const ConvexSupport& inB,
                             float inInflationB, float inMaxDistance)
{
    GjkResult result;
    GjkSimplex& s = result.mSimplex;

    Vec3 v = inA.GetCenter() - inB.GetCenter();
    if (v.squaredNorm() < 1.0e-12f) v = Vec3::UnitX();

    float weights[4] = {1.0f, 0.0f, 0.0f, 0.0f};
    float prevDistSq = cLargeFloat;
    const float maxDistSq = inMaxDistance * inMaxDistance;
    for (int iter = 0; iter < cMaxIterations; ++iter)
    {
        const Vec3 a = inA.GetSupport(-v, inInflationA);
        const Vec3 b = inB.GetSupport(v, inInflationB);
        const Vec3 w = a - b;
        const float vw = v.dot(w);
        const float vSq = v.squaredNorm();

        // dot(v, w) / |v| is a lower bound of the distance: stop as soon as it exceeds the query range
        if (vw > 0.0f && vw * vw > maxDistSq * vSq)
        {
            result.mBeyondMaxDistance = true;
            return result;
        }

        if (s.mCount > 0)
        {
            // No further progress along v: v is the closest point up to float precision. The second term is
            // the rounding error of dot(v, w) itself; without it GJK keeps adding points coplanar with the
            // closest face and can end up with a flat tetrahedron that seems to contain the origin.
            const float vLen = std::sqrt(vSq);
            if (vSq - vw <= 1.0e-5f * vSq + 1.0e-6f * vLen * (vLen + w.norm())) break;
            bool duplicate = false;
            for (int i = 0; i < s.mCount; ++i)
                duplicate |= (s.mY[i] - w).squaredNorm() <= 1.0e-14f * (1.0f + w.squaredNorm());
            if (duplicate) break;
        }

        // Kept to roll back a step that made things worse through float noise
        const GjkSimplex previous = s;
        float previousWeights[4];
        std::copy(weights, weights + 4, previousWeights);
        const Vec3 previousV = v;

        s.mY[s.mCount] = w;
        s.mA[s.mCount] = a;
        s.mB[s.mCount] = b;
        ++s.mCount;

        if (!ReduceSimplex(s, weights, v))
        {
            result.mOverlapping = true;
            return result;
        }
        const float distSq = v.squaredNorm();
        if (distSq <= cOverlapDistance * cOverlapDistance)
        {
            result.mOverlapping = true;
            return result;
        }
        if (distSq >= prevDistSq)
        {
            s = previous;
            std::copy(previousWeights, previousWeights + 4, weights);
            v = previousV;
            break;
        }
        prevDistSq = distSq;
    }

    result.mPointA = Vec3::Zero();
    result.mPointB = Vec3::Zero();
    for (int i = 0; i < s.mCount; ++i)
    {
        result.mPointA += weights[i] * s.mA[i];
        result.mPointB += weights[i] * s.mB[i];
    }
    result.mDistance = std::sqrt(v.squaredNorm());
    return result;
}

} // namespace cairn::physics
