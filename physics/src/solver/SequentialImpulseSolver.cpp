#include "solver/SequentialImpulseSolver.h"

#include "body/Integration.h"
#include "cairn/physics/body/Body.h"

#include <algorithm>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace cairn::physics
{

namespace
{
void InitAxis(const Vec3& inAxis, const Vec3& inRA, const Vec3& inRB, const Mat3& inInvIA,
              const Mat3& inInvIB, float inInvMassA, float inInvMassB, AxisImpulse& outAxis)
{
    outAxis.mRAxAxis = inRA.cross(inAxis);
    outAxis.mRBxAxis = inRB.cross(inAxis);
    outAxis.mInvIA_RAxAxis = inInvIA * outAxis.mRAxAxis;
    outAxis.mInvIB_RBxAxis = inInvIB * outAxis.mRBxAxis;
    const float k = inInvMassA + inInvMassB + outAxis.mRAxAxis.dot(outAxis.mInvIA_RAxAxis) +
                    outAxis.mRBxAxis.dot(outAxis.mInvIB_RBxAxis);
    outAxis.mEffectiveMass = k > 0.0f ? 1.0f / k : 0.0f;
    outAxis.mAccumulated = 0.0f;
}

#if defined(__SSE2__)
/// x0 y0 + (x1 y1 + x2 y2), lane by lane: how Eigen sums a dot product of 3-vectors and each row of a 3x3
/// matrix times a vector, kept so that the results are the scalar code's bit for bit.
inline __m128 Dot3(__m128 inX0, __m128 inX1, __m128 inX2, __m128 inY0, __m128 inY1, __m128 inY2)
{
    return _mm_add_ps(_mm_mul_ps(inX0, inY0), _mm_add_ps(_mm_mul_ps(inX1, inY1), _mm_mul_ps(inX2, inY2)));
}

static_assert(sizeof(AxisImpulse) == 14 * sizeof(float), "AxisImpulse is 14 floats in a row");

/// The normal axes and approach velocities of a manifold's points (inRA/inRB: their arms), one point per SSE
/// lane: lane by lane the arithmetic of InitAxis and of InitConstraint's approach velocity, with the same
/// results bit for bit. One point at a time this was a fifth of the constraint set-up. inNormalVelocity: the
/// normal component of B's linear velocity relative to A's.
void InitNormalAxes(ContactConstraint& ioC, const Vec3 (&inRA)[4], const Vec3 (&inRB)[4], const Mat3& inInvIA,
                    const Mat3& inInvIB, float inInvMassA, float inInvMassB, float inNormalVelocity,
                    const Vec3& inAngularA, const Vec3& inAngularB)
{
    auto lanes = [](const Vec3(&inV)[4], int inK)
    { return _mm_setr_ps(inV[0][inK], inV[1][inK], inV[2][inK], inV[3][inK]); };
    auto splat = [](float inValue) { return _mm_set1_ps(inValue); };
    const __m128 n[3] = {splat(ioC.mNormal.x()), splat(ioC.mNormal.y()), splat(ioC.mNormal.z())};
    // r x n, as Eigen's cross
    auto crossNormal = [&](const Vec3(&inR)[4], __m128(&outRxN)[3])
    {
        const __m128 r[3] = {lanes(inR, 0), lanes(inR, 1), lanes(inR, 2)};
        for (int k = 0; k < 3; ++k)
            outRxN[k] = _mm_sub_ps(_mm_mul_ps(r[(k + 1) % 3], n[(k + 2) % 3]),
                                   _mm_mul_ps(r[(k + 2) % 3], n[(k + 1) % 3]));
    };
    auto timesMatrix = [&](const Mat3& inM, const __m128(&inV)[3], __m128(&outV)[3])
    {
        for (int row = 0; row < 3; ++row)
            outV[row] =
                Dot3(splat(inM(row, 0)), splat(inM(row, 1)), splat(inM(row, 2)), inV[0], inV[1], inV[2]);
    };
    auto dot = [](const __m128(&inA)[3], const __m128(&inB)[3])
    { return Dot3(inA[0], inA[1], inA[2], inB[0], inB[1], inB[2]); };
    __m128 rAxN[3], rBxN[3], invIA_rAxN[3], invIB_rBxN[3];
    crossNormal(inRA, rAxN);
    crossNormal(inRB, rBxN);
    timesMatrix(inInvIA, rAxN, invIA_rAxN);
    timesMatrix(inInvIB, rBxN, invIB_rBxN);
    const __m128 k =
        _mm_add_ps(_mm_add_ps(splat(inInvMassA + inInvMassB), dot(rAxN, invIA_rAxN)), dot(rBxN, invIB_rBxN));
    const __m128 effectiveMass = _mm_and_ps(_mm_cmpgt_ps(k, _mm_setzero_ps()), _mm_div_ps(splat(1.0f), k));
    const __m128 angularA[3] = {splat(inAngularA.x()), splat(inAngularA.y()), splat(inAngularA.z())};
    const __m128 angularB[3] = {splat(inAngularB.x()), splat(inAngularB.y()), splat(inAngularB.z())};
    const __m128 approach =
        _mm_sub_ps(_mm_add_ps(splat(inNormalVelocity), dot(rBxN, angularB)), dot(rAxN, angularA));
    // The rows of the four AxisImpulses, in their field order: rA x n, rB x n, their inertia products, the
    // effective mass and the accumulated impulse (zero)
    const __m128 zero = _mm_setzero_ps();
    const __m128 rows[16] = {rAxN[0],       rAxN[1],       rAxN[2],       rBxN[0],
                             rBxN[1],       rBxN[2],       invIA_rAxN[0], invIA_rAxN[1],
                             invIA_rAxN[2], invIB_rBxN[0], invIB_rBxN[1], invIB_rBxN[2],
                             effectiveMass, zero,          zero,          zero};
    alignas(16) float approachLanes[4];
    _mm_store_ps(approachLanes, approach);
    // Four rows at a time turned into four points' runs of four floats; the last run is two floats
    for (int first = 0; first < 16; first += 4)
    {
        __m128 r0 = rows[first], r1 = rows[first + 1], r2 = rows[first + 2], r3 = rows[first + 3];
        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
        const __m128 points[4] = {r0, r1, r2, r3};
        for (int i = 0; i < ioC.mNumPoints; ++i)
        {
            float* axis = reinterpret_cast<float*>(&ioC.mPoints[i].mNormal);
            if (first < 12)
                _mm_storeu_ps(axis + first, points[i]);
            else
                _mm_storel_pi(reinterpret_cast<__m64*>(axis + first), points[i]);
        }
    }
    for (int i = 0; i < ioC.mNumPoints; ++i)
        ioC.mPoints[i].mApproachVelocity = approachLanes[i];
}
#endif

/// The two solver bodies of a constraint.
struct BodyPair
{
    SolverBody& mA;
    SolverBody& mB;
};

[[gnu::always_inline]] inline BodyPair BodiesOf(const ContactConstraint& inC, std::span<SolverBody> ioBodies)
{
    return {ioBodies[inC.mSolverBodyA], ioBodies[inC.mSolverBodyB]};
}

/// Relative velocity of B with respect to A along an axis. Always inlined: it is most of the solver's work,
/// and as a call it cost a fifth of the step
[[gnu::always_inline]] inline float RelativeVelocity(const BodyPair& inBodies, const Vec3& inAxis,
                                                     const AxisImpulse& inPart)
{
    return inAxis.dot(inBodies.mB.mLinearVelocity - inBodies.mA.mLinearVelocity) +
           inPart.mRBxAxis.dot(inBodies.mB.mAngularVelocity) -
           inPart.mRAxAxis.dot(inBodies.mA.mAngularVelocity);
}

/// Applies impulse inLambda along inAxis: B is pushed along +axis, A along -axis. No test for the motion
/// type: a static or kinematic body has zero inverse mass and inertia, and a block of its own per constraint
/// (see IslandSolver::Solve), so the write changes nothing and races with no other island
[[gnu::always_inline]] inline void ApplyImpulse(const BodyPair& ioBodies, const Vec3& inAxis,
                                                const AxisImpulse& inPart, float inLambda)
{
    ioBodies.mA.mLinearVelocity -= (ioBodies.mA.mInverseMass * inLambda) * inAxis;
    ioBodies.mA.mAngularVelocity -= inLambda * inPart.mInvIA_RAxAxis;
    ioBodies.mB.mLinearVelocity += (ioBodies.mB.mInverseMass * inLambda) * inAxis;
    ioBodies.mB.mAngularVelocity += inLambda * inPart.mInvIB_RBxAxis;
}

/// Relative angular velocity of B with respect to A about the normal.
[[gnu::always_inline]] inline float RelativeTwist(const ContactConstraint& inC, const BodyPair& inBodies)
{
    return inC.mNormal.dot(inBodies.mB.mAngularVelocity - inBodies.mA.mAngularVelocity);
}

[[gnu::always_inline]] inline void ApplyTwist(const ContactConstraint& inC, const BodyPair& ioBodies,
                                              float inLambda)
{
    ioBodies.mA.mAngularVelocity -= inLambda * inC.mInvIA_Normal;
    ioBodies.mB.mAngularVelocity += inLambda * inC.mInvIB_Normal;
}

#if defined(__SSE2__)
/// A constraint's two solver bodies held in registers through its whole velocity iteration: every row of the
/// manifold reads what the one before wrote, and in memory each of those reads waited on the store before it.
/// The two blocks are never the same one (a static or kinematic side has a block of its own). Lane by lane
/// the arithmetic is the scalar functions' below, in their order, so the velocities are the same bit for bit
/// (the wide solver, which tests compare with this one, does the same sums).
struct RegisterBodies
{
    RegisterBodies(const SolverBody& inA, const SolverBody& inB)
        : mLinearA(_mm_load_ps(&inA.mLinearVelocity.x())), mAngularA(_mm_load_ps(&inA.mAngularVelocity.x())),
          mLinearB(_mm_load_ps(&inB.mLinearVelocity.x())), mAngularB(_mm_load_ps(&inB.mAngularVelocity.x())),
          mInverseMassA(inA.mInverseMass), mInverseMassB(inB.mInverseMass)
    {
    }
    void Store(SolverBody& outA, SolverBody& outB) const
    {
        _mm_store_ps(&outA.mLinearVelocity.x(), mLinearA);
        _mm_store_ps(&outA.mAngularVelocity.x(), mAngularA);
        _mm_store_ps(&outB.mLinearVelocity.x(), mLinearB);
        _mm_store_ps(&outB.mAngularVelocity.x(), mAngularB);
    }

    /// The blocks' rows; their fourth lanes (inverse mass, padding) are stored back as they were loaded
    __m128 mLinearA, mAngularA, mLinearB, mAngularB;
    float mInverseMassA, mInverseMassB;
};

/// A Vec3 field as a register, its fourth lane zeroed. The load reads the float after the field, which every
/// Vec3 read here has in its struct.
[[gnu::always_inline]] inline __m128 Load3(const Vec3& inV)
{
    return _mm_and_ps(_mm_loadu_ps(inV.data()), _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0)));
}

/// x + (y + z) of the register's first three lanes: Eigen's sum of a 3-vector dot product
[[gnu::always_inline]] inline float Sum3(__m128 inV)
{
    const float y = _mm_cvtss_f32(_mm_shuffle_ps(inV, inV, _MM_SHUFFLE(1, 1, 1, 1)));
    const float z = _mm_cvtss_f32(_mm_movehl_ps(inV, inV));
    return _mm_cvtss_f32(inV) + (y + z);
}

[[gnu::always_inline]] inline float RelativeVelocity(const RegisterBodies& inBodies, const Vec3& inAxis,
                                                     const AxisImpulse& inPart)
{
    const float along = Sum3(_mm_mul_ps(Load3(inAxis), _mm_sub_ps(inBodies.mLinearB, inBodies.mLinearA)));
    const float turnB = Sum3(_mm_mul_ps(Load3(inPart.mRBxAxis), inBodies.mAngularB));
    const float turnA = Sum3(_mm_mul_ps(Load3(inPart.mRAxAxis), inBodies.mAngularA));
    return along + turnB - turnA;
}

[[gnu::always_inline]] inline void ApplyImpulse(RegisterBodies& ioBodies, const Vec3& inAxis,
                                                const AxisImpulse& inPart, float inLambda)
{
    const __m128 axis = Load3(inAxis), lambda = _mm_set1_ps(inLambda);
    ioBodies.mLinearA =
        _mm_sub_ps(ioBodies.mLinearA, _mm_mul_ps(_mm_set1_ps(ioBodies.mInverseMassA * inLambda), axis));
    ioBodies.mAngularA = _mm_sub_ps(ioBodies.mAngularA, _mm_mul_ps(lambda, Load3(inPart.mInvIA_RAxAxis)));
    ioBodies.mLinearB =
        _mm_add_ps(ioBodies.mLinearB, _mm_mul_ps(_mm_set1_ps(ioBodies.mInverseMassB * inLambda), axis));
    ioBodies.mAngularB = _mm_add_ps(ioBodies.mAngularB, _mm_mul_ps(lambda, Load3(inPart.mInvIB_RBxAxis)));
}

[[gnu::always_inline]] inline float RelativeTwist(const ContactConstraint& inC,
                                                  const RegisterBodies& inBodies)
{
    return Sum3(_mm_mul_ps(Load3(inC.mNormal), _mm_sub_ps(inBodies.mAngularB, inBodies.mAngularA)));
}

[[gnu::always_inline]] inline void ApplyTwist(const ContactConstraint& inC, RegisterBodies& ioBodies,
                                              float inLambda)
{
    const __m128 lambda = _mm_set1_ps(inLambda);
    ioBodies.mAngularA = _mm_sub_ps(ioBodies.mAngularA, _mm_mul_ps(lambda, Load3(inC.mInvIA_Normal)));
    ioBodies.mAngularB = _mm_add_ps(ioBodies.mAngularB, _mm_mul_ps(lambda, Load3(inC.mInvIB_Normal)));
}
#endif

float TotalNormalImpulse(const ContactConstraint& inC)
{
    float total = 0.0f;
    for (int i = 0; i < inC.mNumPoints; ++i)
        total += inC.mPoints[i].mNormal.mAccumulated;
    return total;
}

template <class Bodies> void SolvePatchFriction(ContactConstraint& ioC, Bodies& ioBodies)
{
    PatchFriction& patch = ioC.mPatch;
    const float maxFriction = ioC.mFriction * TotalNormalImpulse(ioC);
    float total[2];
    for (int t = 0; t < 2; ++t)
        total[t] =
            patch.mTangent[t].mAccumulated -
            patch.mTangent[t].mEffectiveMass * RelativeVelocity(ioBodies, ioC.mTangent[t], patch.mTangent[t]);
    // Clamp to the friction circle rather than a box, so sliding friction is mu * N in every direction
    const float lengthSq = total[0] * total[0] + total[1] * total[1];
    if (lengthSq > maxFriction * maxFriction)
    {
        const float scale = lengthSq > 0.0f ? maxFriction / std::sqrt(lengthSq) : 0.0f;
        total[0] *= scale;
        total[1] *= scale;
    }
    for (int t = 0; t < 2; ++t)
    {
        const float applied = total[t] - patch.mTangent[t].mAccumulated;
        patch.mTangent[t].mAccumulated = total[t];
        ApplyImpulse(ioBodies, ioC.mTangent[t], patch.mTangent[t], applied);
    }

    // Twist: the torsional friction of a contact patch of mean radius r is at most mu * N * r
    const float maxTwist = maxFriction * patch.mTwistRadius;
    const float twist =
        std::clamp(patch.mTwistAccumulated - patch.mTwistEffectiveMass * RelativeTwist(ioC, ioBodies),
                   -maxTwist, maxTwist);
    ApplyTwist(ioC, ioBodies, twist - patch.mTwistAccumulated);
    patch.mTwistAccumulated = twist;
}

template <class Bodies>
[[gnu::always_inline]] inline void SolveNormal(const ContactConstraint& inC, Bodies& ioBodies,
                                               ContactConstraintPoint& ioP)
{
    const float vn = RelativeVelocity(ioBodies, inC.mNormal, ioP.mNormal);
    const float total =
        std::max(ioP.mNormal.mAccumulated + ioP.mNormal.mEffectiveMass * (ioP.mVelocityBias - vn), 0.0f);
    const float applied = total - ioP.mNormal.mAccumulated;
    ioP.mNormal.mAccumulated = total;
    ioP.mMaxNormalImpulse = std::max(ioP.mMaxNormalImpulse, total);
    ApplyImpulse(ioBodies, inC.mNormal, ioP.mNormal, applied);
}
} // namespace

void SequentialImpulseSolver::InitConstraint(Body& ioA, Body& ioB, const Mat3& inInvIA, const Mat3& inInvIB,
                                             const ContactManifold& inManifold, float inDeltaTime,
                                             ContactConstraint& outConstraint, const Vec3* inLocalOnA,
                                             const Vec3* inLocalOnB)
{
    ContactConstraint& c = outConstraint;
    c.mBodyA = &ioA;
    c.mBodyB = &ioB;
    c.mNormal = inManifold.mNormal;
    c.mTangent[0] = AnyPerpendicular(c.mNormal);
    c.mTangent[1] = c.mNormal.cross(c.mTangent[0]);
    // Geometric mean: a frictionless surface makes every contact with it frictionless (as Jolt and Box2D do)
    c.mFriction = std::sqrt(ioA.GetFriction() * ioB.GetFriction());
    // Max: a bouncy ball bounces on any floor
    c.mRestitution = std::max(ioA.GetRestitution(), ioB.GetRestitution());
    c.mNumPoints = inManifold.mNumPoints;

    const Mat3& invIA = inInvIA;
    const Mat3& invIB = inInvIB;
    const Vec3& xA = ioA.GetCenterOfMassPosition();
    const Vec3& xB = ioB.GetCenterOfMassPosition();
    Vec3 centroid = Vec3::Zero();
    Vec3 rA[ContactManifold::cMaxPoints] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    Vec3 rB[ContactManifold::cMaxPoints] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    for (int i = 0; i < c.mNumPoints; ++i)
    {
        const ContactPoint& mp = inManifold.mPoints[i];
        ContactConstraintPoint& p = c.mPoints[i];
        rA[i] = mp.mPositionOnA - xA;
        rB[i] = mp.mPositionOnB - xB;
        p.mLocalOnA = inLocalOnA != nullptr ? inLocalOnA[i] : Vec3(ioA.GetRotation().conjugate() * rA[i]);
        p.mLocalOnB = inLocalOnB != nullptr ? inLocalOnB[i] : Vec3(ioB.GetRotation().conjugate() * rB[i]);
        // A speculative point (separated by s) may close its gap this step, but no more
        p.mSeparation = -mp.mPenetration;
        p.mVelocityBias = p.mSeparation > 0.0f ? -p.mSeparation / inDeltaTime : 0.0f;
        p.mMaxNormalImpulse = 0.0f;
        p.mBounceVelocity = 0.0f;
        centroid += 0.5f * (mp.mPositionOnA + mp.mPositionOnB);
    }
    // Each point's normal axis, and its normal velocity before solving
    const float normalVelocity = c.mNormal.dot(ioB.GetLinearVelocity() - ioA.GetLinearVelocity());
#if defined(__SSE2__)
    InitNormalAxes(c, rA, rB, invIA, invIB, ioA.GetInverseMass(), ioB.GetInverseMass(), normalVelocity,
                   ioA.GetAngularVelocity(), ioB.GetAngularVelocity());
#else
    for (int i = 0; i < c.mNumPoints; ++i)
    {
        ContactConstraintPoint& p = c.mPoints[i];
        InitAxis(c.mNormal, rA[i], rB[i], invIA, invIB, ioA.GetInverseMass(), ioB.GetInverseMass(),
                 p.mNormal);
        p.mApproachVelocity = normalVelocity + p.mNormal.mRBxAxis.dot(ioB.GetAngularVelocity()) -
                              p.mNormal.mRAxAxis.dot(ioA.GetAngularVelocity());
    }
#endif
    centroid /= float(std::max(c.mNumPoints, 1));

    PatchFriction& patch = c.mPatch;
    for (int t = 0; t < 2; ++t)
        InitAxis(c.mTangent[t], centroid - xA, centroid - xB, invIA, invIB, ioA.GetInverseMass(),
                 ioB.GetInverseMass(), patch.mTangent[t]);
    c.mInvIA_Normal = invIA * c.mNormal;
    c.mInvIB_Normal = invIB * c.mNormal;
    const float twistK = c.mNormal.dot(c.mInvIA_Normal + c.mInvIB_Normal);
    patch.mTwistEffectiveMass = twistK > 0.0f ? 1.0f / twistK : 0.0f;
    patch.mTwistAccumulated = 0.0f;
    patch.mTwistRadius = 0.0f;
    for (int i = 0; i < c.mNumPoints; ++i)
    {
        const Vec3 offset =
            0.5f * (inManifold.mPoints[i].mPositionOnA + inManifold.mPoints[i].mPositionOnB) - centroid;
        patch.mTwistRadius += (offset - offset.dot(c.mNormal) * c.mNormal).norm();
    }
    patch.mTwistRadius /= float(std::max(c.mNumPoints, 1));
}

void SequentialImpulseSolver::WarmStart(std::span<ContactConstraint* const> ioConstraints,
                                        std::span<SolverBody> ioBodies)
{
    for (ContactConstraint* c : ioConstraints)
    {
        const BodyPair bodies = BodiesOf(*c, ioBodies);
        for (int i = 0; i < c->mNumPoints; ++i)
            ApplyImpulse(bodies, c->mNormal, c->mPoints[i].mNormal, c->mPoints[i].mNormal.mAccumulated);
        for (int t = 0; t < 2; ++t)
            ApplyImpulse(bodies, c->mTangent[t], c->mPatch.mTangent[t], c->mPatch.mTangent[t].mAccumulated);
        ApplyTwist(*c, bodies, c->mPatch.mTwistAccumulated);
    }
}

void SequentialImpulseSolver::SolveVelocities(std::span<ContactConstraint* const> ioConstraints,
                                              std::span<SolverBody> ioBodies, int inIteration)
{
    const bool backwards = (inIteration & 1) != 0;
    for (ContactConstraint* c : ioConstraints)
    {
        const BodyPair blocks = BodiesOf(*c, ioBodies);
#if defined(__SSE2__)
        RegisterBodies bodies(blocks.mA, blocks.mB);
#else
        const BodyPair& bodies = blocks;
#endif
        // Friction first, against last iteration's normal impulse: normal is solved last so that
        // non-penetration, the more important constraint, wins when the two disagree
        SolvePatchFriction(*c, bodies);
        if (backwards)
            for (int i = c->mNumPoints - 1; i >= 0; --i)
                SolveNormal(*c, bodies, c->mPoints[i]);
        else
            for (int i = 0; i < c->mNumPoints; ++i)
                SolveNormal(*c, bodies, c->mPoints[i]);
#if defined(__SSE2__)
        bodies.Store(blocks.mA, blocks.mB);
#endif
    }
}

void SequentialImpulseSolver::InitBounces(const VelocityChange& inA, const VelocityChange& inB,
                                          float inDeltaTime, const SolverSettings& inSettings,
                                          ContactConstraint& ioC)
{
    const float linearChange = ioC.mNormal.dot(inB.mLinear - inA.mLinear);
    for (int i = 0; i < ioC.mNumPoints; ++i)
    {
        ContactConstraintPoint& p = ioC.mPoints[i];
        // The point bounces in the step it would reach the surface in: a gap it closes this step, or a touch
        const float gap = std::max(p.mSeparation, 0.0f);
        const float velocity = p.mApproachVelocity; // Before the contacts, after the step's forces
        if (!(gap + velocity * inDeltaTime < 0.0f)) continue;
        // Along the normal the point moves as a body under constant acceleration a (the forces' and gravity's
        // share of the relative velocity). Symplectic Euler's positions lie on the parabola whose velocity at
        // the step's start is s = v_before + a dt / 2; it reaches the surface at speed sqrt(s^2 - 2 a gap),
        // leaves it e times as fast, and is back at the gap with speed sqrt(e^2 v_hit^2 + 2 a gap). Starting
        // from there now, the velocity the position half needs is that plus a dt / 2. So the bounce is the
        // analytic one from wherever in the step the surface is met: with e = 1 the velocity is exactly
        // reversed (the parabola mirrored), so no bounce gains or loses height, and gravity acting during the
        // impact step adds nothing to the rebound
        const float change =
            linearChange + p.mNormal.mRBxAxis.dot(inB.mAngular) - p.mNormal.mRAxAxis.dot(inA.mAngular);
        const float acceleration = change / inDeltaTime;
        const float startVelocity =
            velocity - 0.5f * change; // The velocity before the step: velocity - change
        const float hitSpeedSq = startVelocity * startVelocity - 2.0f * acceleration * gap;
        if (!(hitSpeedSq >= inSettings.mRestitutionThreshold * inSettings.mRestitutionThreshold)) continue;
        const float leaveSpeedSq =
            ioC.mRestitution * ioC.mRestitution * hitSpeedSq + 2.0f * acceleration * gap;
        p.mBounceVelocity = std::max(std::sqrt(std::max(leaveSpeedSq, 0.0f)) + 0.5f * change, 0.0f);
        // The target of every velocity iteration, not of a pass after them: the contacts behind the other
        // body (a box on a stack) then push back while it bounces, as the stack would
        p.mVelocityBias = std::max(p.mVelocityBias, p.mBounceVelocity);
    }
}

void SequentialImpulseSolver::ApplyRestitution(std::span<ContactConstraint* const> ioConstraints,
                                               std::span<SolverBody> ioBodies)
{
    for (ContactConstraint* c : ioConstraints)
    {
        if (c->mRestitution == 0.0f) continue;
        const BodyPair bodies = BodiesOf(*c, ioBodies);
        for (int i = 0; i < c->mNumPoints; ++i)
        {
            ContactConstraintPoint& p = c->mPoints[i];
            // Only points that touched (received an impulse: another contact may have stopped the body short)
            if (p.mBounceVelocity == 0.0f || p.mMaxNormalImpulse == 0.0f) continue;
            const float vn = RelativeVelocity(bodies, c->mNormal, p.mNormal);
            const float lambda = -p.mNormal.mEffectiveMass * (vn - p.mBounceVelocity);
            const float total = std::max(p.mNormal.mAccumulated + lambda, 0.0f);
            const float applied = total - p.mNormal.mAccumulated;
            p.mNormal.mAccumulated = total;
            ApplyImpulse(bodies, c->mNormal, p.mNormal, applied);
        }
    }
}

void SequentialImpulseSolver::MakePositionConstraint(const ContactConstraint& inConstraint,
                                                     PositionConstraint& outConstraint)
{
    outConstraint.mBodyA = inConstraint.mBodyA;
    outConstraint.mBodyB = inConstraint.mBodyB;
    outConstraint.mNormal = inConstraint.mNormal;
    outConstraint.mNumPoints = inConstraint.mNumPoints;
    for (int i = 0; i < inConstraint.mNumPoints; ++i)
    {
        outConstraint.mLocalOnA[i] = inConstraint.mPoints[i].mLocalOnA;
        outConstraint.mLocalOnB[i] = inConstraint.mPoints[i].mLocalOnB;
    }
}

float SequentialImpulseSolver::SolvePositions(std::span<const PositionConstraint> inConstraints,
                                              const SolverSettings& inSettings)
{
    float maxPenetration = 0.0f;
    for (const PositionConstraint& c : inConstraints)
    {
        Body& a = *c.mBodyA;
        Body& b = *c.mBodyB;
        // The world inverse inertias are made on the first point that needs a correction: in a settled stack
        // most constraints need none
        Mat3 invIA = Mat3::Zero(), invIB = Mat3::Zero(); // Set before use; zeroed so no path reads garbage
        bool haveInertia = false;
        for (int i = 0; i < c.mNumPoints; ++i)
        {
            // Penetration from the bodies' current poses (they moved since the manifold was made)
            const Vec3 rA = a.GetRotation() * c.mLocalOnA[i];
            const Vec3 rB = b.GetRotation() * c.mLocalOnB[i];
            const float separation =
                c.mNormal.dot((b.GetCenterOfMassPosition() + rB) - (a.GetCenterOfMassPosition() + rA));
            maxPenetration = std::max(maxPenetration, -separation - inSettings.mPenetrationSlop);
            const float correction =
                std::clamp(inSettings.mBaumgarte * (separation + inSettings.mPenetrationSlop),
                           -inSettings.mMaxPenetrationCorrection, 0.0f);
            if (correction == 0.0f) continue;
            if (!haveInertia)
            {
                invIA = a.GetInverseInertiaWorld();
                invIB = b.GetInverseInertiaWorld();
                haveInertia = true;
            }
            AxisImpulse axis;
            InitAxis(c.mNormal, rA, rB, invIA, invIB, a.GetInverseMass(), b.GetInverseMass(), axis);
            const float impulse = -correction * axis.mEffectiveMass;
            // Move positions directly (a pseudo-impulse): it corrects the overlap without adding velocity
            if (a.IsDynamic())
                Integration::CorrectPose(a, -((a.GetInverseMass() * impulse) * c.mNormal),
                                         -impulse * axis.mInvIA_RAxAxis);
            if (b.IsDynamic())
                Integration::CorrectPose(b, (b.GetInverseMass() * impulse) * c.mNormal,
                                         impulse * axis.mInvIB_RBxAxis);
        }
    }
    return maxPenetration;
}

} // namespace cairn::physics
