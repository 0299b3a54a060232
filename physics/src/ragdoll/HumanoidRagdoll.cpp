#include "cairn/physics/ragdoll/HumanoidRagdoll.h"

#include "cairn/physics/shapes/CapsuleShape.h"
#include "cairn/physics/shapes/SphereShape.h"

#include <algorithm>
#include <array>

namespace cairn::physics
{

namespace
{
/// A bone of the 1.8 m figure: from its joint with the parent to its far end (m), its thickness, its parent
/// (-1: the root), the plane axis of its joint (across the bone: the joint's frame), and the joint's half
/// cone angles and twist range (rad)
struct Bone
{
    Vec3 mFrom;
    Vec3 mTo;
    float mRadius;
    int32_t mParent;
    Vec3 mPlaneAxis;
    float mNormalHalfCone;
    float mPlaneHalfCone;
    float mTwist;
};

/// One side's limb bones from its shoulder (+x: the figure's left); mirrored for the right
constexpr float cShoulderY = 1.45f;
} // namespace

RagdollSettings MakeHumanoidRagdoll(float inHeight)
{
    const float scale = std::clamp(inHeight, 0.5f, 3.0f) / 1.8f;
    const Vec3 x = Vec3::UnitX(), z = Vec3::UnitZ();
    // Indices: 0 pelvis, 1-3 spine, 4 chest, 5 neck, 6 head, then per side (left, then right) clavicle,
    // upper arm, forearm, hand, then per side thigh, shin, foot, toes
    std::vector<Bone> bones = {
        {{0, 0.92f, 0}, {0, 1.02f, 0}, 0.13f, -1, x, 0, 0, 0},
        {{0, 1.02f, 0}, {0, 1.14f, 0}, 0.12f, 0, x, 0.25f, 0.25f, 0.2f},
        {{0, 1.14f, 0}, {0, 1.26f, 0}, 0.12f, 1, x, 0.25f, 0.25f, 0.2f},
        {{0, 1.26f, 0}, {0, 1.36f, 0}, 0.13f, 2, x, 0.25f, 0.25f, 0.2f},
        {{0, 1.36f, 0}, {0, 1.48f, 0}, 0.14f, 3, x, 0.2f, 0.2f, 0.2f},
        {{0, 1.48f, 0}, {0, 1.58f, 0}, 0.05f, 4, x, 0.4f, 0.4f, 0.5f},
        {{0, 1.58f, 0}, {0, 1.80f, 0}, 0.1f, 5, x, 0.3f, 0.3f, 0.4f},
    };
    for (const float side : {1.0f, -1.0f})
    {
        const int32_t chest = 4, first = int32_t(bones.size());
        bones.push_back({{side * 0.03f, cShoulderY, 0},
                         {side * 0.18f, cShoulderY, 0},
                         0.04f,
                         chest,
                         z,
                         0.15f,
                         0.15f,
                         0.05f});
        bones.push_back({{side * 0.18f, cShoulderY, 0},
                         {side * 0.45f, cShoulderY, 0},
                         0.05f,
                         first,
                         z,
                         1.0f,
                         1.2f,
                         0.6f});
        // The elbow bends in the horizontal plane only (about y): its normal half cone nearly closed
        bones.push_back({{side * 0.45f, cShoulderY, 0},
                         {side * 0.71f, cShoulderY, 0},
                         0.04f,
                         first + 1,
                         z,
                         0.05f,
                         1.2f,
                         0.05f});
        bones.push_back({{side * 0.71f, cShoulderY, 0},
                         {side * 0.87f, cShoulderY, 0},
                         0.04f,
                         first + 2,
                         z,
                         0.5f,
                         0.3f,
                         0.3f});
    }
    for (const float side : {1.0f, -1.0f})
    {
        const int32_t pelvis = 0, first = int32_t(bones.size());
        bones.push_back(
            {{side * 0.1f, 0.92f, 0}, {side * 0.1f, 0.5f, 0}, 0.07f, pelvis, x, 0.8f, 0.5f, 0.4f});
        // The knee bends about x only: its plane half cone (about the normal, z) nearly closed
        bones.push_back(
            {{side * 0.1f, 0.5f, 0}, {side * 0.1f, 0.09f, 0}, 0.05f, first, x, 1.0f, 0.05f, 0.05f});
        bones.push_back({{side * 0.1f, 0.08f, -0.02f},
                         {side * 0.1f, 0.05f, 0.14f},
                         0.04f,
                         first + 1,
                         x,
                         0.4f,
                         0.2f,
                         0.2f});
        bones.push_back({{side * 0.1f, 0.05f, 0.14f},
                         {side * 0.1f, 0.04f, 0.22f},
                         0.03f,
                         first + 2,
                         x,
                         0.4f,
                         0.05f,
                         0.05f});
    }

    RagdollSettings settings;
    settings.mParts.resize(bones.size());
    for (size_t i = 0; i < bones.size(); ++i)
    {
        const Bone& bone = bones[i];
        const Vec3 from = bone.mFrom * scale, to = bone.mTo * scale;
        const float radius = bone.mRadius * scale;
        const Vec3 along = to - from;
        const float halfHeight = 0.5f * along.norm() - radius;
        RagdollPart& part = settings.mParts[i];
        BodyCreationSettings& body = part.mBody;
        body.mPosition = 0.5f * (from + to);
        // A capsule along the bone where it is long enough to have a cylinder, else a ball
        if (halfHeight > 0.01f * scale)
        {
            body.mShape = CapsuleShape::Create(halfHeight, radius).Value();
            body.mRotation = Quat::FromTwoVectors(Vec3::UnitY(), along.normalized());
        }
        else
            body.mShape = SphereShape::Create(radius).Value();
        body.mFriction = 0.6f;
        part.mParent = bone.mParent;
        if (bone.mParent < 0) continue;
        SwingTwistConstraintSettings& joint = part.mJoint;
        joint.mPoint = from;
        joint.mTwistAxis = along.normalized();
        joint.mPlaneAxis =
            (bone.mPlaneAxis - bone.mPlaneAxis.dot(joint.mTwistAxis) * joint.mTwistAxis).normalized();
        joint.mNormalHalfConeAngle = bone.mNormalHalfCone;
        joint.mPlaneHalfConeAngle = bone.mPlaneHalfCone;
        joint.mTwistMinAngle = -bone.mTwist;
        joint.mTwistMaxAngle = bone.mTwist;
        joint.mMaxFrictionTorque = 0.5f * scale; // A little: limbs settle instead of twitching
    }
    settings.DisableCollisionsOfTouchingParts(0.02f * scale);
    return settings;
}

} // namespace cairn::physics
