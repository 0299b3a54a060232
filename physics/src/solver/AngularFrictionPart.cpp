#include "solver/AngularFrictionPart.h"

namespace cairn::physics
{

void AngularFrictionPart::Prepare(const JointBodyMass& inA, const JointBodyMass& inB, const Mat3& inFrame,
                                  float inBound)
{
    Mat3 effectiveMass;
    if (!(inBound > 0.0f && InvertJointMassMatrix(inA.mInverseInertia + inB.mInverseInertia, effectiveMass)))
    {
        Deactivate();
        return;
    }
    mActive = true;
    // The impulse J (frame axes) acts on the spins as the world torque impulse frame J; the one that stops a
    // relative spin w is -K^-1 w in the world, frame^T of that in the frame (the frame is orthonormal)
    mImpulsePerSpin = inFrame.transpose() * effectiveMass;
    mSpinPerImpulseA = inA.mInverseInertia * inFrame;
    mSpinPerImpulseB = inB.mInverseInertia * inFrame;
    mBound = inBound;
    mTotalImpulse = mTotalImpulse.cwiseMax(-inBound).cwiseMin(inBound);
}

void AngularFrictionPart::WarmStart(SolverBody& ioA, SolverBody& ioB, float inRatio)
{
    mTotalImpulse *= inRatio;
    if (mActive) Apply(ioA, ioB, mTotalImpulse);
}

} // namespace cairn::physics
