#include "narrowphase/Epa.h"

#include "narrowphase/ClosestPoints.h"

#include <algorithm>

namespace cairn::physics
{

namespace
{

struct EpaVertex
{
    Vec3 mY;
    Vec3 mA;
    Vec3 mB;
};

struct EpaFace
{
    int mV[3];
    Vec3 mNormal;    ///< Outward unit normal
    float mDistance; ///< Signed distance of the face plane from the origin
    bool mAlive;
};

struct EpaEdge
{
    int mFrom;
    int mTo;
};

class Polytope
{
public:
    Polytope(const ConvexSupport& inA, float inInflationA, const ConvexSupport& inB, float inInflationB)
        : mA(inA), mB(inB), mInflationA(inInflationA), mInflationB(inInflationB)
    {
    }

    EpaVertex Support(const Vec3& inDirection) const
    {
        EpaVertex v;
        v.mA = mA.GetSupport(inDirection, mInflationA);
        v.mB = mB.GetSupport(-inDirection, mInflationB);
        v.mY = v.mA - v.mB;
        return v;
    }

    int AddVertex(const EpaVertex& inVertex)
    {
        if (mNumVertices >= Epa::cMaxVertices) return -1;
        mVertices[mNumVertices] = inVertex;
        return mNumVertices++;
    }

    bool AddFace(int inV0, int inV1, int inV2)
    {
        if (mNumFaces >= Epa::cMaxFaces) return false;
        EpaFace& f = mFaces[mNumFaces++];
        f.mV[0] = inV0;
        f.mV[1] = inV1;
        f.mV[2] = inV2;
        const Vec3& y0 = mVertices[inV0].mY;
        const Vec3 n = (mVertices[inV1].mY - y0).cross(mVertices[inV2].mY - y0);
        const float len = n.norm();
        f.mAlive = true;
        if (len > 1.0e-20f)
        {
            f.mNormal = n / len;
            f.mDistance = f.mNormal.dot(y0);
        }
        else
        {
            // A sliver: never pick it as closest, but keep it so the surface stays closed
            f.mNormal = Vec3::Zero();
            f.mDistance = cLargeFloat;
        }
        return true;
    }

    // Builds a tetrahedron around the origin from the GJK simplex, adding support points as needed
    bool Initialize(const GjkSimplex& inSimplex)
    {
        for (int i = 0; i < inSimplex.mCount; ++i)
            AddVertex({inSimplex.mY[i], inSimplex.mA[i], inSimplex.mB[i]});
        const float scale = 1.0f + std::max(mA.GetCenter().norm(), mB.GetCenter().norm());
        const float eps = 1.0e-6f * scale;

        if (mNumVertices == 0) AddVertex(Support(Vec3::UnitX()));
        if (mNumVertices == 1)
        {
            static const Vec3 cDirs[6] = {Vec3::UnitX(),  -Vec3::UnitX(), Vec3::UnitY(),
                                          -Vec3::UnitY(), Vec3::UnitZ(),  -Vec3::UnitZ()};
            for (const Vec3& d : cDirs)
            {
                const EpaVertex v = Support(d);
                if ((v.mY - mVertices[0].mY).norm() > eps)
                {
                    AddVertex(v);
                    break;
                }
            }
        }
        if (mNumVertices == 2)
        {
            // Search around the segment for the point furthest from its line
            const Vec3 axis = (mVertices[1].mY - mVertices[0].mY).normalized();
            const Vec3 perp = AnyPerpendicular(axis);
            EpaVertex best = mVertices[0];
            float bestDist = -1.0f;
            for (int k = 0; k < 6; ++k)
            {
                const float angle = static_cast<float>(k) * (cPi / 3.0f);
                const Vec3 dir = Eigen::AngleAxisf(angle, axis) * perp;
                const EpaVertex v = Support(dir);
                const Vec3 rel = v.mY - mVertices[0].mY;
                const float dist = (rel - rel.dot(axis) * axis).norm();
                if (dist > bestDist)
                {
                    bestDist = dist;
                    best = v;
                }
            }
            if (bestDist > eps) AddVertex(best);
        }
        if (mNumVertices == 3)
        {
            const Vec3& y0 = mVertices[0].mY;
            const Vec3 n = (mVertices[1].mY - y0).cross(mVertices[2].mY - y0).normalized();
            const EpaVertex up = Support(n);
            const EpaVertex down = Support(-n);
            const float dUp = n.dot(up.mY - y0);
            const float dDown = -n.dot(down.mY - y0);
            // Prefer the side of the origin so the tetrahedron contains it; otherwise the side with volume
            const bool originAbove = n.dot(-y0) > 0.0f;
            if (originAbove ? dUp > eps : dDown <= eps)
                AddVertex(up);
            else
                AddVertex(down);
        }
        if (mNumVertices < 4) return false;

        const Vec3& y0 = mVertices[0].mY;
        const float volume = (mVertices[1].mY - y0).cross(mVertices[2].mY - y0).dot(mVertices[3].mY - y0);
        if (std::abs(volume) < 1.0e-12f * scale * scale * scale) return false;
        // Faces below are outward when vertex 3 is below the plane of (0, 1, 2)
        if (volume > 0.0f) std::swap(mVertices[1], mVertices[2]);
        AddFace(0, 1, 2);
        AddFace(0, 3, 1);
        AddFace(0, 2, 3);
        AddFace(1, 3, 2);
        return true;
    }

    int ClosestFace() const
    {
        int best = -1;
        float bestDist = cLargeFloat;
        for (int i = 0; i < mNumFaces; ++i)
            if (mFaces[i].mAlive && mFaces[i].mDistance < bestDist)
            {
                bestDist = mFaces[i].mDistance;
                best = i;
            }
        return best;
    }

    // Adds inVertex, removing every face that sees it and closing the hole; false when out of capacity
    bool Expand(const EpaVertex& inVertex)
    {
        const int newIndex = AddVertex(inVertex);
        if (newIndex < 0) return false;
        const Vec3& w = inVertex.mY;
        const float eps = 1.0e-7f * (1.0f + w.norm());

        int numEdges = 0;
        for (int i = 0; i < mNumFaces; ++i)
        {
            EpaFace& f = mFaces[i];
            if (!f.mAlive || f.mNormal.dot(w - mVertices[f.mV[0]].mY) <= eps) continue;
            f.mAlive = false;
            for (int k = 0; k < 3; ++k)
            {
                const int from = f.mV[k];
                const int to = f.mV[(k + 1) % 3];
                // An edge shared by two removed faces is interior to the hole: the reverse cancels it
                bool cancelled = false;
                for (int e = 0; e < numEdges; ++e)
                    if (mEdges[e].mFrom == to && mEdges[e].mTo == from)
                    {
                        mEdges[e] = mEdges[--numEdges];
                        cancelled = true;
                        break;
                    }
                if (!cancelled)
                {
                    if (numEdges >= cMaxEdges) return false;
                    mEdges[numEdges++] = {from, to};
                }
            }
        }
        // Reuse dead face slots first so long runs do not exhaust the face array
        int write = 0;
        for (int i = 0; i < mNumFaces; ++i)
            if (mFaces[i].mAlive) mFaces[write++] = mFaces[i];
        mNumFaces = write;
        for (int e = 0; e < numEdges; ++e)
            if (!AddFace(mEdges[e].mFrom, mEdges[e].mTo, newIndex)) return false;
        return numEdges > 0;
    }

    const EpaFace& GetFace(int inIndex) const { return mFaces[inIndex]; }
    const EpaVertex& GetVertex(int inIndex) const { return mVertices[inIndex]; }

private:
    static constexpr int cMaxEdges = 128;

    const ConvexSupport& mA;
    const ConvexSupport& mB;
    float mInflationA;
    float mInflationB;
    int mNumVertices = 0;
    int mNumFaces = 0;
    EpaVertex mVertices[Epa::cMaxVertices];
    EpaFace mFaces[Epa::cMaxFaces];
    EpaEdge mEdges[cMaxEdges];
};

} // namespace

bool Epa::Penetration(const ConvexSupport& inA, float inInflationA, const ConvexSupport& inB,
                      float inInflationB, const GjkSimplex& inSimplex, PenetrationResult& outResult)
{
    Polytope poly(inA, inInflationA, inB, inInflationB);
    if (!poly.Initialize(inSimplex)) return false;

    int closest = poly.ClosestFace();
    if (closest < 0) return false;
    EpaFace best = poly.GetFace(closest);
    for (int iter = 0; iter < cMaxIterations; ++iter)
    {
        const EpaVertex w = poly.Support(best.mNormal);
        const float supportDist = w.mY.dot(best.mNormal);
        // The true depth lies between the face distance and the support distance along its normal
        if (supportDist - best.mDistance <= 1.0e-5f + 1.0e-4f * std::abs(supportDist)) break;
        // When the polytope cannot grow any more, the face we have is the best estimate
        if (!poly.Expand(w)) break;
        closest = poly.ClosestFace();
        if (closest < 0) break;
        best = poly.GetFace(closest);
    }
    if (best.mDistance >= cLargeFloat) return false;

    // The origin's projection on the closest face, as weights of its three vertices, gives both points
    const EpaVertex& v0 = poly.GetVertex(best.mV[0]);
    const EpaVertex& v1 = poly.GetVertex(best.mV[1]);
    const EpaVertex& v2 = poly.GetVertex(best.mV[2]);
    Vec3 bary;
    uint32_t feature;
    ClosestPointOnTriangle(best.mNormal * best.mDistance, v0.mY, v1.mY, v2.mY, bary, feature);
    outResult.mNormal = best.mNormal;
    outResult.mDepth = best.mDistance;
    outResult.mPointA = bary.x() * v0.mA + bary.y() * v1.mA + bary.z() * v2.mA;
    outResult.mPointB = bary.x() * v0.mB + bary.y() * v1.mB + bary.z() * v2.mB;
    return true;
}

} // namespace cairn::physics
