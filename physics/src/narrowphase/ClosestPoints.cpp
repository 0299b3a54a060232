#include "narrowphase/ClosestPoints.h"

#include <algorithm>

namespace cairn::physics
{

Vec3 ClosestPointOnSegment(const Vec3& inP, const Vec3& inA, const Vec3& inB, float& outT)
{
    const Vec3 ab = inB - inA;
    const float lenSq = ab.squaredNorm();
    outT = lenSq > 0.0f ? std::clamp((inP - inA).dot(ab) / lenSq, 0.0f, 1.0f) : 0.0f;
    return inA + outT * ab;
}

float ClosestPointsSegmentSegment(const Vec3& inP1, const Vec3& inQ1, const Vec3& inP2, const Vec3& inQ2,
                                  float& outS, float& outT, Vec3& outC1, Vec3& outC2)
{
    const Vec3 d1 = inQ1 - inP1;
    const Vec3 d2 = inQ2 - inP2;
    const Vec3 r = inP1 - inP2;
    const float a = d1.squaredNorm();
    const float e = d2.squaredNorm();
    const float f = d2.dot(r);
    // Relative to the segment lengths so that tiny and huge shapes behave the same
    const float eps = 1.0e-12f * std::max(1.0f, std::max(a, e));

    if (a <= eps && e <= eps)
    {
        outS = outT = 0.0f;
    }
    else if (a <= eps)
    {
        outS = 0.0f;
        outT = std::clamp(f / e, 0.0f, 1.0f);
    }
    else
    {
        const float c = d1.dot(r);
        if (e <= eps)
        {
            outT = 0.0f;
            outS = std::clamp(-c / a, 0.0f, 1.0f);
        }
        else
        {
            const float b = d1.dot(d2);
            const float denom = a * e - b * b;
            // Parallel segments have denom 0: any s works, take the start and let the clamps below fix t
            outS = denom > eps * a * e ? std::clamp((b * f - c * e) / denom, 0.0f, 1.0f) : 0.0f;
            outT = (b * outS + f) / e;
            if (outT < 0.0f)
            {
                outT = 0.0f;
                outS = std::clamp(-c / a, 0.0f, 1.0f);
            }
            else if (outT > 1.0f)
            {
                outT = 1.0f;
                outS = std::clamp((b - c) / a, 0.0f, 1.0f);
            }
        }
    }
    outC1 = inP1 + d1 * outS;
    outC2 = inP2 + d2 * outT;
    return (outC1 - outC2).squaredNorm();
}

Vec3 ClosestPointOnTriangle(const Vec3& inP, const Vec3& inA, const Vec3& inB, const Vec3& inC, Vec3& outBary,
                            uint32_t& outFeature)
{
    // Voronoi region tests on the vertices, then the edges, then the interior
    const Vec3 ab = inB - inA;
    const Vec3 ac = inC - inA;
    const Vec3 ap = inP - inA;
    const float d1 = ab.dot(ap);
    const float d2 = ac.dot(ap);
    if (d1 <= 0.0f && d2 <= 0.0f)
    {
        outBary = Vec3(1.0f, 0.0f, 0.0f);
        outFeature = 0b001;
        return inA;
    }
    const Vec3 bp = inP - inB;
    const float d3 = ab.dot(bp);
    const float d4 = ac.dot(bp);
    if (d3 >= 0.0f && d4 <= d3)
    {
        outBary = Vec3(0.0f, 1.0f, 0.0f);
        outFeature = 0b010;
        return inB;
    }
    const Vec3 cp = inP - inC;
    const float d5 = ab.dot(cp);
    const float d6 = ac.dot(cp);
    if (d6 >= 0.0f && d5 <= d6)
    {
        outBary = Vec3(0.0f, 0.0f, 1.0f);
        outFeature = 0b100;
        return inC;
    }
    const float vc = d1 * d4 - d3 * d2;
    const float vb = d5 * d2 - d1 * d6;
    const float va = d3 * d6 - d5 * d4;
    const float sum = va + vb + vc;
    // A collinear triangle has no interior and its region tests are unreliable: take the best edge
    const bool degenerate = !(sum > 1.0e-12f * (ab.squaredNorm() * ac.squaredNorm() + 1.0e-30f));
    if (degenerate)
    {
        float t;
        const Vec3 e0 = ClosestPointOnSegment(inP, inA, inB, t);
        Vec3 bestBary(1.0f - t, t, 0.0f);
        Vec3 best = e0;
        float bestSq = (inP - e0).squaredNorm();
        const Vec3 e1 = ClosestPointOnSegment(inP, inB, inC, t);
        if ((inP - e1).squaredNorm() < bestSq)
        {
            best = e1;
            bestSq = (inP - e1).squaredNorm();
            bestBary = Vec3(0.0f, 1.0f - t, t);
        }
        const Vec3 e2 = ClosestPointOnSegment(inP, inC, inA, t);
        if ((inP - e2).squaredNorm() < bestSq)
        {
            best = e2;
            bestBary = Vec3(t, 0.0f, 1.0f - t);
        }
        outBary = bestBary;
        outFeature = (bestBary.x() > 0.0f ? 0b001u : 0u) | (bestBary.y() > 0.0f ? 0b010u : 0u) |
                     (bestBary.z() > 0.0f ? 0b100u : 0u);
        return best;
    }
    if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f)
    {
        const float v = d1 / (d1 - d3);
        outBary = Vec3(1.0f - v, v, 0.0f);
        outFeature = 0b011;
        return inA + v * ab;
    }
    if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f)
    {
        const float w = d2 / (d2 - d6);
        outBary = Vec3(1.0f - w, 0.0f, w);
        outFeature = 0b101;
        return inA + w * ac;
    }
    if (va <= 0.0f && d4 - d3 >= 0.0f && d5 - d6 >= 0.0f)
    {
        const float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        outBary = Vec3(0.0f, 1.0f - w, w);
        outFeature = 0b110;
        return inB + w * (inC - inB);
    }
    const float v = vb / sum;
    const float w = vc / sum;
    outBary = Vec3(1.0f - v - w, v, w);
    outFeature = 0b111;
    return inA + v * ab + w * ac;
}

} // namespace cairn::physics
