#include "cairn/physics/body/Body.h"

#include <Eigen/Eigenvalues>

namespace cairn::physics
{

void Body::Init(const BodyID& inID, const BodyCreationSettings& inSettings)
{
    mID = inID;
    mShape = inSettings.mShape;
    mMotionType = inSettings.mMotionType;
    mObjectLayer = inSettings.mObjectLayer;
    mRotation = inSettings.mRotation.normalized();
    mFriction = inSettings.mFriction;
    mRestitution = inSettings.mRestitution;
    mLinearDamping = inSettings.mLinearDamping;
    mAngularDamping = inSettings.mAngularDamping;
    mGravityFactor = inSettings.mGravityFactor;
    mMaxLinearVelocity = inSettings.mMaxLinearVelocity;
    mMaxAngularVelocity = inSettings.mMaxAngularVelocity;
    mAllowSleeping = inSettings.mAllowSleeping;
    mNavMeshArea = inSettings.mNavMeshArea;
    mUserData = inSettings.mUserData;
    mForce.setZero();
    mTorque.setZero();
    mSleepTimer = 0.0f;
    SetActiveIndex(cInactive);
    mInWorld = false;
    mAddPending = false;
    mWakeIsland = false;
    mSleepRingNext = inID;

    mInvMass = 0.0f;
    mInvInertiaDiagonal.setZero();
    mInertiaRotation.setIdentity();
    mCenterOfMassOffset.setZero();
    if (mMotionType == MotionType::Dynamic)
    {
        const MassProperties mass = mShape->GetMassProperties(inSettings.mDensity);
        mInvMass = 1.0f / mass.mMass;
        mCenterOfMassOffset = mass.mCenterOfMass;
        // Store the inertia as principal moments plus the rotation to the principal axes: the solver then
        // needs only a diagonal in the rotated frame
        Eigen::SelfAdjointEigenSolver<Mat3> solver(mass.mInertia);
        Mat3 axes = solver.eigenvectors();
        if (axes.determinant() < 0.0f) axes.col(2) = -axes.col(2); // a reflection is not a rotation
        mInertiaRotation = Quat(axes).normalized();
        const Vec3 moments = solver.eigenvalues();
        for (int i = 0; i < 3; ++i)
        {
            // A moment too small to invert (a tiny body) turns as if infinitely stiff about that axis rather
            // than with an infinite inverse, which the step would make NaN
            const float inverse = moments[i] > 0.0f ? 1.0f / moments[i] : 0.0f;
            mInvInertiaDiagonal[i] = std::isfinite(inverse) ? inverse : 0.0f;
        }
    }
    else if (mMotionType == MotionType::Kinematic)
    {
        // A kinematic body rotates about its centre of mass like a dynamic one would
        mCenterOfMassOffset = mShape->GetMassProperties(1.0f).mCenterOfMass;
    }

    if (mMotionType == MotionType::Static)
    {
        mLinearVelocity.setZero();
        mAngularVelocity.setZero();
    }
    else
    {
        mLinearVelocity = inSettings.mLinearVelocity;
        mAngularVelocity = inSettings.mAngularVelocity;
    }
    mPosition = inSettings.mPosition + mRotation * mCenterOfMassOffset;
    UpdateBounds();
}

} // namespace cairn::physics
