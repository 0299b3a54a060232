#include "narrowphase/CollideConvexConvex.h"

#include "narrowphase/FaceClipping.h"

namespace cairn::physics
{

namespace
{

void WorldSupportingFace(const ConvexShape& inShape, const Transform& inTransform,
                         const Vec3& inWorldDirection, SupportingFace& outFace)
{
    inShape.GetSupportingFace(inTransform.InverseRotateVector(inWorldDirection), outFace);
    const Mat3 r = inTransform.mRotation.toRotationMatrix();
    for (int i = 0; i < outFace.mCount; ++i)
        outFace.mVertices[i] = r * outFace.mVertices[i] + inTransform.mPosition;
}

} // namespace

void ManifoldFromContact(const ConvexShape& inA, const Transform& inTransformA, const ConvexShape& inB,
                         const Transform& inTransformB, const ConvexContact& inContact, float inMaxSeparation,
                         ContactManifold& outManifold)
{
    outManifold.mNormal = inContact.mNormal;
    SupportingFace faceA;
    SupportingFace faceB;
    WorldSupportingFace(inA, inTransformA, inContact.mNormal, faceA);
    WorldSupportingFace(inB, inTransformB, -inContact.mNormal, faceB);
    if (faceA.mCount >= 2 || faceB.mCount >= 2)
    {
        if (ManifoldFromFaces(faceA.mVertices, faceA.mCount, faceB.mVertices, faceB.mCount, inContact.mNormal,
                              inMaxSeparation, outManifold) > 0)
        {
            KeepTheContactGap({inContact.mPointA, inContact.mPointB, inContact.mPenetration}, outManifold);
            return;
        }
    }
    outManifold.mNumPoints = 1;
    outManifold.mPoints[0] = {inContact.mPointA, inContact.mPointB, inContact.mPenetration};
}

bool CollideConvexConvex(const ConvexShape& inA, const Transform& inTransformA, const ConvexShape& inB,
                         const Transform& inTransformB, const CollideSettings& inSettings,
                         ContactManifold& outManifold)
{
    const ConvexSupport a = ConvexSupport::FromShape(inA, inTransformA);
    const ConvexSupport b = ConvexSupport::FromShape(inB, inTransformB);
    ConvexContact contact;
    if (!FindConvexContact(a, b, inSettings.mMaxSeparation, contact)) return false;
    ManifoldFromContact(inA, inTransformA, inB, inTransformB, contact, inSettings.mMaxSeparation,
                        outManifold);
    return true;
}

} // namespace cairn::physics
