#include "WideContactSolver.h"

#if CAIRN_WIDE_SOLVER

#include <algorithm>
#include <cstring>

namespace cairn::physics
{
namespace
{
static_assert(sizeof(SolverBody) == 32 && alignof(SolverBody) == 32, "two aligned 16-byte rows per body");

/// A 3-vector for four lanes.
struct Vec3x4
{
    __m128 mX, mY, mZ;
};

/// Velocities of the four lanes' A or B bodies.
struct BodiesX4
{
    Vec3x4 mLinear;
    Vec3x4 mAngular;
    __m128 mInverseMass;
    __m128 mPadding; ///< Carried so the store writes back what it loaded
};

float* Floats(SolverBody& ioBody)
{
    return reinterpret_cast<float*>(&ioBody);
}

/// Rows (v.xyz, 1/m) and (w.xyz, pad) of four blocks, turned into columns.
[[gnu::always_inline]] inline BodiesX4 Gather(std::span<SolverBody> inBodies, const uint32_t inIndex[4])
{
    __m128 l0 = _mm_load_ps(Floats(inBodies[inIndex[0]]));
    __m128 l1 = _mm_load_ps(Floats(inBodies[inIndex[1]]));
    __m128 l2 = _mm_load_ps(Floats(inBodies[inIndex[2]]));
    __m128 l3 = _mm_load_ps(Floats(inBodies[inIndex[3]]));
    __m128 a0 = _mm_load_ps(Floats(inBodies[inIndex[0]]) + 4);
    __m128 a1 = _mm_load_ps(Floats(inBodies[inIndex[1]]) + 4);
    __m128 a2 = _mm_load_ps(Floats(inBodies[inIndex[2]]) + 4);
    __m128 a3 = _mm_load_ps(Floats(inBodies[inIndex[3]]) + 4);
    _MM_TRANSPOSE4_PS(l0, l1, l2, l3);
    _MM_TRANSPOSE4_PS(a0, a1, a2, a3);
    return {{l0, l1, l2}, {a0, a1, a2}, l3, a3};
}

[[gnu::always_inline]] inline void Scatter(BodiesX4 inValues, std::span<SolverBody> ioBodies,
                                           const uint32_t inIndex[4])
{
    __m128 l0 = inValues.mLinear.mX, l1 = inValues.mLinear.mY, l2 = inValues.mLinear.mZ,
           l3 = inValues.mInverseMass;
    __m128 a0 = inValues.mAngular.mX, a1 = inValues.mAngular.mY, a2 = inValues.mAngular.mZ,
           a3 = inValues.mPadding;
    _MM_TRANSPOSE4_PS(l0, l1, l2, l3);
    _MM_TRANSPOSE4_PS(a0, a1, a2, a3);
    _mm_store_ps(Floats(ioBodies[inIndex[0]]), l0);
    _mm_store_ps(Floats(ioBodies[inIndex[1]]), l1);
    _mm_store_ps(Floats(ioBodies[inIndex[2]]), l2);
    _mm_store_ps(Floats(ioBodies[inIndex[3]]), l3);
    _mm_store_ps(Floats(ioBodies[inIndex[0]]) + 4, a0);
    _mm_store_ps(Floats(ioBodies[inIndex[1]]) + 4, a1);
    _mm_store_ps(Floats(ioBodies[inIndex[2]]) + 4, a2);
    _mm_store_ps(Floats(ioBodies[inIndex[3]]) + 4, a3);
}

// The arithmetic below follows the scalar solver operation by operation. Eigen's dot product of 3-vectors
// sums as x0 y0 + (x1 y1 + x2 y2), and that grouping is kept here

[[gnu::always_inline]] inline __m128 Dot(const __m128 inA[3], __m128 inX, __m128 inY, __m128 inZ)
{
    return _mm_add_ps(_mm_mul_ps(inA[0], inX), _mm_add_ps(_mm_mul_ps(inA[1], inY), _mm_mul_ps(inA[2], inZ)));
}

[[gnu::always_inline]] inline __m128 RelativeVelocity(const BodiesX4& inA, const BodiesX4& inB,
                                                      const __m128 inAxis[3], const WideAxis& inPart)
{
    const __m128 along =
        Dot(inAxis, _mm_sub_ps(inB.mLinear.mX, inA.mLinear.mX), _mm_sub_ps(inB.mLinear.mY, inA.mLinear.mY),
            _mm_sub_ps(inB.mLinear.mZ, inA.mLinear.mZ));
    const __m128 turnB = Dot(inPart.mRBxAxis, inB.mAngular.mX, inB.mAngular.mY, inB.mAngular.mZ);
    const __m128 turnA = Dot(inPart.mRAxAxis, inA.mAngular.mX, inA.mAngular.mY, inA.mAngular.mZ);
    return _mm_sub_ps(_mm_add_ps(along, turnB), turnA);
}

[[gnu::always_inline]] inline void ApplyImpulse(BodiesX4& ioA, BodiesX4& ioB, const __m128 inAxis[3],
                                                const WideAxis& inPart, __m128 inLambda)
{
    const __m128 linearA = _mm_mul_ps(ioA.mInverseMass, inLambda);
    ioA.mLinear.mX = _mm_sub_ps(ioA.mLinear.mX, _mm_mul_ps(linearA, inAxis[0]));
    ioA.mLinear.mY = _mm_sub_ps(ioA.mLinear.mY, _mm_mul_ps(linearA, inAxis[1]));
    ioA.mLinear.mZ = _mm_sub_ps(ioA.mLinear.mZ, _mm_mul_ps(linearA, inAxis[2]));
    ioA.mAngular.mX = _mm_sub_ps(ioA.mAngular.mX, _mm_mul_ps(inLambda, inPart.mInvIA_RAxAxis[0]));
    ioA.mAngular.mY = _mm_sub_ps(ioA.mAngular.mY, _mm_mul_ps(inLambda, inPart.mInvIA_RAxAxis[1]));
    ioA.mAngular.mZ = _mm_sub_ps(ioA.mAngular.mZ, _mm_mul_ps(inLambda, inPart.mInvIA_RAxAxis[2]));
    const __m128 linearB = _mm_mul_ps(ioB.mInverseMass, inLambda);
    ioB.mLinear.mX = _mm_add_ps(ioB.mLinear.mX, _mm_mul_ps(linearB, inAxis[0]));
    ioB.mLinear.mY = _mm_add_ps(ioB.mLinear.mY, _mm_mul_ps(linearB, inAxis[1]));
    ioB.mLinear.mZ = _mm_add_ps(ioB.mLinear.mZ, _mm_mul_ps(linearB, inAxis[2]));
    ioB.mAngular.mX = _mm_add_ps(ioB.mAngular.mX, _mm_mul_ps(inLambda, inPart.mInvIB_RBxAxis[0]));
    ioB.mAngular.mY = _mm_add_ps(ioB.mAngular.mY, _mm_mul_ps(inLambda, inPart.mInvIB_RBxAxis[1]));
    ioB.mAngular.mZ = _mm_add_ps(ioB.mAngular.mZ, _mm_mul_ps(inLambda, inPart.mInvIB_RBxAxis[2]));
}

[[gnu::always_inline]] inline void ApplyTwist(const WideContactBatch& inC, BodiesX4& ioA, BodiesX4& ioB,
                                              __m128 inLambda)
{
    ioA.mAngular.mX = _mm_sub_ps(ioA.mAngular.mX, _mm_mul_ps(inLambda, inC.mInvIA_Normal[0]));
    ioA.mAngular.mY = _mm_sub_ps(ioA.mAngular.mY, _mm_mul_ps(inLambda, inC.mInvIA_Normal[1]));
    ioA.mAngular.mZ = _mm_sub_ps(ioA.mAngular.mZ, _mm_mul_ps(inLambda, inC.mInvIA_Normal[2]));
    ioB.mAngular.mX = _mm_add_ps(ioB.mAngular.mX, _mm_mul_ps(inLambda, inC.mInvIB_Normal[0]));
    ioB.mAngular.mY = _mm_add_ps(ioB.mAngular.mY, _mm_mul_ps(inLambda, inC.mInvIB_Normal[1]));
    ioB.mAngular.mZ = _mm_add_ps(ioB.mAngular.mZ, _mm_mul_ps(inLambda, inC.mInvIB_Normal[2]));
}

[[gnu::always_inline]] inline void SolvePatchFriction(WideContactBatch& ioC, BodiesX4& ioA, BodiesX4& ioB)
{
    // The points' accumulated impulses summed in order (padding points are zero and change nothing)
    __m128 normalTotal = ioC.mPoint[0].mAccumulated;
    for (int i = 1; i < ContactManifold::cMaxPoints; ++i)
        normalTotal = _mm_add_ps(normalTotal, ioC.mPoint[i].mAccumulated);
    const __m128 maxFriction = _mm_mul_ps(ioC.mFriction, normalTotal);
    __m128 total[2];
    for (int t = 0; t < 2; ++t)
        total[t] = _mm_sub_ps(ioC.mTangentAxis[t].mAccumulated,
                              _mm_mul_ps(ioC.mTangentAxis[t].mEffectiveMass,
                                         RelativeVelocity(ioA, ioB, ioC.mTangent[t], ioC.mTangentAxis[t])));
    // Clamped to the friction circle in the lanes that leave it. There maxFriction^2 < lengthSq, so the
    // length is not zero and the scalar solver's guard against it never applies
    const __m128 lengthSq = _mm_add_ps(_mm_mul_ps(total[0], total[0]), _mm_mul_ps(total[1], total[1]));
    const __m128 outside = _mm_cmpgt_ps(lengthSq, _mm_mul_ps(maxFriction, maxFriction));
    const __m128 scale = _mm_div_ps(maxFriction, _mm_sqrt_ps(lengthSq));
    for (int t = 0; t < 2; ++t)
    {
        total[t] =
            _mm_or_ps(_mm_and_ps(outside, _mm_mul_ps(total[t], scale)), _mm_andnot_ps(outside, total[t]));
        const __m128 applied = _mm_sub_ps(total[t], ioC.mTangentAxis[t].mAccumulated);
        ioC.mTangentAxis[t].mAccumulated = total[t];
        ApplyImpulse(ioA, ioB, ioC.mTangent[t], ioC.mTangentAxis[t], applied);
    }

    const __m128 maxTwist = _mm_mul_ps(maxFriction, ioC.mTwistRadius);
    const __m128 minTwist = _mm_xor_ps(maxTwist, _mm_set1_ps(-0.0f)); // Negated, as -maxTwist
    const __m128 relativeTwist =
        Dot(ioC.mNormal, _mm_sub_ps(ioB.mAngular.mX, ioA.mAngular.mX),
            _mm_sub_ps(ioB.mAngular.mY, ioA.mAngular.mY), _mm_sub_ps(ioB.mAngular.mZ, ioA.mAngular.mZ));
    const __m128 unclamped =
        _mm_sub_ps(ioC.mTwistAccumulated, _mm_mul_ps(ioC.mTwistEffectiveMass, relativeTwist));
    // std::clamp(v, lo, hi) is v < lo ? lo : (hi < v ? hi : v); _mm_max_ps(a, b) is a > b ? a : b
    const __m128 twist = _mm_min_ps(maxTwist, _mm_max_ps(minTwist, unclamped));
    ApplyTwist(ioC, ioA, ioB, _mm_sub_ps(twist, ioC.mTwistAccumulated));
    ioC.mTwistAccumulated = twist;
}

[[gnu::always_inline]] inline void SolveNormal(WideContactBatch& ioC, int inPoint, BodiesX4& ioA,
                                               BodiesX4& ioB)
{
    WideAxis& axis = ioC.mPoint[inPoint];
    const __m128 vn = RelativeVelocity(ioA, ioB, ioC.mNormal, axis);
    // std::max(x, 0) is x < 0 ? 0 : x, which _mm_max_ps(0, x) matches (NaN included)
    const __m128 total =
        _mm_max_ps(_mm_setzero_ps(),
                   _mm_add_ps(axis.mAccumulated,
                              _mm_mul_ps(axis.mEffectiveMass, _mm_sub_ps(ioC.mVelocityBias[inPoint], vn))));
    const __m128 applied = _mm_sub_ps(total, axis.mAccumulated);
    axis.mAccumulated = total;
    ioC.mMaxNormalImpulse[inPoint] = _mm_max_ps(total, ioC.mMaxNormalImpulse[inPoint]);
    ApplyImpulse(ioA, ioB, ioC.mNormal, axis, applied);
}

void SetLane(__m128& ioVector, int inLane, float inValue)
{
    reinterpret_cast<float*>(&ioVector)[inLane] = inValue;
}
float GetLane(const __m128& inVector, int inLane)
{
    return reinterpret_cast<const float*>(&inVector)[inLane];
}

void SetLane(__m128 (&ioVector)[3], int inLane, const Vec3& inValue)
{
    for (int i = 0; i < 3; ++i)
        SetLane(ioVector[i], inLane, inValue[i]);
}

// A WideAxis's 14 rows are AxisImpulse's 14 floats in the same order, so packing four of them is a 4x4
// transpose per run of four floats (lane by lane it was 56 scalar stores, half of Pack)
static_assert(sizeof(AxisImpulse) == 14 * sizeof(float) && sizeof(WideAxis) == 14 * sizeof(__m128),
              "WideAxis rows mirror AxisImpulse's floats");
constexpr int cAxisFloats = 14;

/// What a lane without an axis (padding, or a point beyond its manifold's count) packs: zeros.
alignas(16) constexpr float cZeroAxis[16] = {};

const float* Floats(const AxisImpulse& inAxis)
{
    return reinterpret_cast<const float*>(&inAxis);
}

/// Four lanes' axes (inLanes[l]: cAxisFloats floats, or cZeroAxis) into outAxis.
void PackAxis(const float* const (&inLanes)[4], WideAxis& outAxis)
{
    __m128* rows = reinterpret_cast<__m128*>(&outAxis);
    for (int k = 0; k + 4 <= cAxisFloats; k += 4)
    {
        __m128 r0 = _mm_loadu_ps(inLanes[0] + k), r1 = _mm_loadu_ps(inLanes[1] + k),
               r2 = _mm_loadu_ps(inLanes[2] + k), r3 = _mm_loadu_ps(inLanes[3] + k);
        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
        rows[k] = r0;
        rows[k + 1] = r1;
        rows[k + 2] = r2;
        rows[k + 3] = r3;
    }
    // The last two rows (effective mass, accumulated): a 16-byte load would read past the axis
    for (int k = cAxisFloats / 4 * 4; k < cAxisFloats; ++k)
        rows[k] = _mm_setr_ps(inLanes[0][k], inLanes[1][k], inLanes[2][k], inLanes[3][k]);
}
} // namespace

void WideContactSolver::Pack(std::span<ContactConstraint* const> inConstraints,
                             std::span<SolverBody> ioBodies, WideContactBatch& ioBatch)
{
    const uint32_t first = ioBatch.mFirst, count = ioBatch.mCount, paddingFirst = ioBatch.mPaddingFirst;
    // All zero: padding lanes and padding points stay so, and an impulse of zero moves nothing
    std::memset(static_cast<void*>(&ioBatch), 0, sizeof(ioBatch));
    ioBatch.mFirst = first;
    ioBatch.mCount = count;
    ioBatch.mPaddingFirst = paddingFirst;
    const ContactConstraint* lanes[4] = {};
    for (uint32_t lane = 0; lane < count; ++lane)
        lanes[lane] = inConstraints[lane];
    const float* axes[4];
    for (int t = 0; t < 2; ++t)
    {
        for (int l = 0; l < 4; ++l)
            axes[l] = lanes[l] != nullptr ? Floats(lanes[l]->mPatch.mTangent[t]) : cZeroAxis;
        PackAxis(axes, ioBatch.mTangentAxis[t]);
    }
    for (int i = 0; i < ContactManifold::cMaxPoints; ++i)
    {
        for (int l = 0; l < 4; ++l)
            axes[l] = lanes[l] != nullptr && i < lanes[l]->mNumPoints ? Floats(lanes[l]->mPoints[i].mNormal)
                                                                      : cZeroAxis;
        PackAxis(axes, ioBatch.mPoint[i]);
    }
    for (uint32_t lane = 0; lane < 4; ++lane)
    {
        if (lanes[lane] == nullptr)
        {
            ioBatch.mBodyA[lane] = paddingFirst + 2 * lane;
            ioBatch.mBodyB[lane] = paddingFirst + 2 * lane + 1;
            ioBatch.mCacheIndex[lane] = cInvalidCacheIndex;
            std::memset(static_cast<void*>(&ioBodies[ioBatch.mBodyA[lane]]), 0, sizeof(SolverBody));
            std::memset(static_cast<void*>(&ioBodies[ioBatch.mBodyB[lane]]), 0, sizeof(SolverBody));
            continue;
        }
        const ContactConstraint& c = *lanes[lane];
        const int l = int(lane);
        ioBatch.mBodyA[lane] = c.mSolverBodyA;
        ioBatch.mBodyB[lane] = c.mSolverBodyB;
        ioBatch.mCacheIndex[lane] = c.mCacheIndex;
        SetLane(ioBatch.mNormal, l, c.mNormal);
        SetLane(ioBatch.mTangent[0], l, c.mTangent[0]);
        SetLane(ioBatch.mTangent[1], l, c.mTangent[1]);
        SetLane(ioBatch.mInvIA_Normal, l, c.mInvIA_Normal);
        SetLane(ioBatch.mInvIB_Normal, l, c.mInvIB_Normal);
        SetLane(ioBatch.mFriction, l, c.mFriction);
        SetLane(ioBatch.mTwistEffectiveMass, l, c.mPatch.mTwistEffectiveMass);
        SetLane(ioBatch.mTwistAccumulated, l, c.mPatch.mTwistAccumulated);
        SetLane(ioBatch.mTwistRadius, l, c.mPatch.mTwistRadius);
        for (int i = 0; i < c.mNumPoints; ++i)
        {
            SetLane(ioBatch.mVelocityBias[i], l, c.mPoints[i].mVelocityBias);
            SetLane(ioBatch.mMaxNormalImpulse[i], l, c.mPoints[i].mMaxNormalImpulse);
        }
    }
}

void WideContactSolver::WarmStart(std::span<const WideContactBatch> inBatches, std::span<SolverBody> ioBodies)
{
    for (const WideContactBatch& batch : inBatches)
    {
        BodiesX4 a = Gather(ioBodies, batch.mBodyA);
        BodiesX4 b = Gather(ioBodies, batch.mBodyB);
        // As the scalar warm start: the points, the two tangents, then the twist (padding applies zero)
        for (int i = 0; i < ContactManifold::cMaxPoints; ++i)
            ApplyImpulse(a, b, batch.mNormal, batch.mPoint[i], batch.mPoint[i].mAccumulated);
        for (int t = 0; t < 2; ++t)
            ApplyImpulse(a, b, batch.mTangent[t], batch.mTangentAxis[t], batch.mTangentAxis[t].mAccumulated);
        ApplyTwist(batch, a, b, batch.mTwistAccumulated);
        Scatter(a, ioBodies, batch.mBodyA);
        Scatter(b, ioBodies, batch.mBodyB);
    }
}

void WideContactSolver::SolveVelocities(std::span<WideContactBatch> ioBatches, std::span<SolverBody> ioBodies,
                                        int inIteration)
{
    const bool backwards = (inIteration & 1) != 0;
    for (WideContactBatch& batch : ioBatches)
    {
        BodiesX4 a = Gather(ioBodies, batch.mBodyA);
        BodiesX4 b = Gather(ioBodies, batch.mBodyB);
        // As the scalar solver: friction against last iteration's normal impulses, then the points forwards
        // or backwards by the iteration's parity
        SolvePatchFriction(batch, a, b);
        if (backwards)
            for (int i = ContactManifold::cMaxPoints - 1; i >= 0; --i)
                SolveNormal(batch, i, a, b);
        else
            for (int i = 0; i < ContactManifold::cMaxPoints; ++i)
                SolveNormal(batch, i, a, b);
        Scatter(a, ioBodies, batch.mBodyA);
        Scatter(b, ioBodies, batch.mBodyB);
    }
}

void WideContactSolver::Unpack(const WideContactBatch& inBatch,
                               std::span<ContactConstraint* const> ioConstraints)
{
    for (uint32_t lane = 0; lane < inBatch.mCount; ++lane)
    {
        if (ioConstraints[lane] == nullptr) continue;
        ContactConstraint& c = *ioConstraints[lane];
        const int l = int(lane);
        c.mPatch.mTwistAccumulated = GetLane(inBatch.mTwistAccumulated, l);
        for (int t = 0; t < 2; ++t)
            c.mPatch.mTangent[t].mAccumulated = GetLane(inBatch.mTangentAxis[t].mAccumulated, l);
        for (int i = 0; i < c.mNumPoints; ++i)
        {
            c.mPoints[i].mNormal.mAccumulated = GetLane(inBatch.mPoint[i].mAccumulated, l);
            c.mPoints[i].mMaxNormalImpulse = GetLane(inBatch.mMaxNormalImpulse[i], l);
        }
    }
}

void WideContactSolver::StoreImpulses(const WideContactBatch& inBatch, ContactCache& ioCache)
{
    for (uint32_t lane = 0; lane < inBatch.mCount; ++lane)
    {
        if (inBatch.mCacheIndex[lane] == cInvalidCacheIndex) continue;
        CachedManifold& cached = ioCache.Get(inBatch.mCacheIndex[lane]);
        const int l = int(lane);
        // Points beyond the lane's count hold zeros, and the cache never reads past its count
        for (int i = 0; i < ContactManifold::cMaxPoints; ++i)
            cached.mNormalImpulse[i] = GetLane(inBatch.mPoint[i].mAccumulated, l);
        const float friction[2] = {GetLane(inBatch.mTangentAxis[0].mAccumulated, l),
                                   GetLane(inBatch.mTangentAxis[1].mAccumulated, l)};
        for (int k = 0; k < 3; ++k)
            cached.mFrictionImpulse[k] = friction[0] * GetLane(inBatch.mTangent[0][k], l) +
                                         friction[1] * GetLane(inBatch.mTangent[1][k], l);
        cached.mTwistImpulse = GetLane(inBatch.mTwistAccumulated, l);
    }
}

} // namespace cairn::physics

#endif
