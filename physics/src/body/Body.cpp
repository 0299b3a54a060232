#include "cairn/physics/body/Body.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

namespace cairn::physics
{

void Body::Init(const BodyID& inID, const BodyCreationSettings& inSettings)
{
    mID = inID;
    mShape = inSettings.mShape;
    mMotionType = inSettings.mMotionType;
    mObjectLayer = inSettings.mObjectLayer;
    mCollisionGroupID = inSettings.mCollisionGroup.mGroupID;
    mCollisionSubGroupID = uint16_t(inSettings.mCollisionGroup.mSubGroupID); // Checked below the table's size
    mRotation = inSettings.mRotation.normalized();
    mFriction = inSettings.mFriction;
    mRestitution = inSettings.mRestitution;
    mLinearDamping = inSettings.mLinearDamping;
    mAngularDamping = inSettings.mAngularDamping;
    mGravityFactor = inSettings.mGravityFactor;
    mDensity = inSettings.mDensity;
    mMaxLinearVelocity = inSettings.mMaxLinearVelocity;
    mMaxAngularVelocity = inSettings.mMaxAngularVelocity;
    mAllowSleeping = inSettings.mAllowSleeping;
    mIsSensor = inSettings.mIsSensor;
    mMotionQuality = inSettings.mMotionQuality;
    mShapeGeneration = 0;
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

    SetMassProperties(true);
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

Status Body::CheckDynamicMass(const Shape& inShape, float inDensity)
{
    auto invalid = [](std::string inWhat)
    { return Status(MakeError(ErrorCode::InvalidArgument, std::move(inWhat))); };
    if (!std::isfinite(inDensity) || inDensity <= 0.0f) return invalid("density must be finite and > 0");
    // The volume first, at unit density, so a density that overflows the mass is not blamed on the shape
    const MassProperties unit = inShape.GetMassProperties(1.0f);
    if (!(unit.mMass > 0.0f) || !std::isfinite(unit.mMass) || !unit.mInertia.allFinite())
        return invalid(std::string("a dynamic body needs a shape with volume; a ") +
                       ToString(inShape.GetType()) + " has none");
    // Beyond cMaxBodyMass a landing body's contact impulses overflow a float and turn it and its neighbours
    // to NaN
    static_assert(cMaxBodyMass == 1.0e12f, "the message below names it");
    const MassProperties mass = inShape.GetMassProperties(inDensity);
    if (!(mass.mMass <= cMaxBodyMass) || !mass.mInertia.allFinite())
        return invalid("the body's mass (density times volume) is over 1e12 kg (cMaxBodyMass)");
    // A mass in the denormals (a density of 1e-40) has an infinite inverse: the first step would make NaN
    if (!std::isfinite(1.0f / mass.mMass))
        return invalid("the body's mass (density times volume) is too small to invert");
    return Status::Ok();
}

void Body::SetMassProperties(bool inRecomputeMass)
{
    if (inRecomputeMass || mMotionType != MotionType::Dynamic)
    {
        mInvMass = 0.0f;
        mInvInertiaDiagonal.setZero();
        mInertiaRotation.setIdentity();
    }
    mCenterOfMassOffset.setZero();
    if (mMotionType == MotionType::Dynamic)
    {
        const MassProperties mass = mShape->GetMassProperties(mDensity);
        mCenterOfMassOffset = mass.mCenterOfMass;
        if (!inRecomputeMass) return;
        mInvMass = 1.0f / mass.mMass;
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
}

} // namespace cairn::physics
