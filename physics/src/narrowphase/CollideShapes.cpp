#include "cairn/physics/narrowphase/CollideShapes.h"

#include "cairn/physics/shapes/CompoundShape.h"
#include "narrowphase/CollideBoxBox.h"
#include "narrowphase/CollideCapsuleCapsule.h"
#include "narrowphase/CollideConvexConvex.h"
#include "narrowphase/CollideConvexTriangles.h"
#include "narrowphase/CollideSphereBox.h"
#include "narrowphase/CollideSphereCapsule.h"
#include "narrowphase/CollideSphereSphere.h"
#include "narrowphase/FaceClipping.h"

#include <utility>

namespace cairn::physics
{

namespace
{

// The same contact seen from the other side: B becomes A
void FlipManifold(ContactManifold& ioManifold)
{
    ioManifold.mNormal = -ioManifold.mNormal;
    for (int i = 0; i < ioManifold.mNumPoints; ++i)
        std::swap(ioManifold.mPoints[i].mPositionOnA, ioManifold.mPoints[i].mPositionOnB);
    std::swap(ioManifold.mSubShapeA, ioManifold.mSubShapeB);
}

bool IsTriangleSoup(ShapeType inType)
{
    return inType == ShapeType::TriangleMesh || inType == ShapeType::HeightField;
}

// Routine for (A, B), or for (B, A) with the result flipped
template <class ShapeA, class ShapeB, class Fn>
bool CollideSwapped(Fn inFn, const ConvexShape& inA, const Transform& inTransformA, const ConvexShape& inB,
                    const Transform& inTransformB, const CollideSettings& inSettings,
                    ContactManifold& outManifold)
{
    if (!inFn(static_cast<const ShapeA&>(inB), inTransformB, static_cast<const ShapeB&>(inA), inTransformA,
              inSettings, outManifold))
        return false;
    FlipManifold(outManifold);
    return true;
}

bool CollideConvexPair(const ConvexShape& inA, const Transform& inTransformA, const ConvexShape& inB,
                       const Transform& inTransformB, const CollideSettings& inSettings,
                       ContactManifold& outManifold)
{
    const ShapeType a = inA.GetType();
    const ShapeType b = inB.GetType();
    using enum ShapeType;
    if (a == Sphere && b == Sphere)
        return CollideSphereSphere(static_cast<const SphereShape&>(inA), inTransformA,
                                   static_cast<const SphereShape&>(inB), inTransformB, inSettings,
                                   outManifold);
    if (a == Sphere && b == Box)
        return CollideSphereBox(static_cast<const SphereShape&>(inA), inTransformA,
                                static_cast<const BoxShape&>(inB), inTransformB, inSettings, outManifold);
    if (a == Box && b == Sphere)
        return CollideSwapped<SphereShape, BoxShape>(CollideSphereBox, inA, inTransformA, inB, inTransformB,
                                                     inSettings, outManifold);
    if (a == Sphere && b == Capsule)
        return CollideSphereCapsule(static_cast<const SphereShape&>(inA), inTransformA,
                                    static_cast<const CapsuleShape&>(inB), inTransformB, inSettings,
                                    outManifold);
    if (a == Capsule && b == Sphere)
        return CollideSwapped<SphereShape, CapsuleShape>(CollideSphereCapsule, inA, inTransformA, inB,
                                                         inTransformB, inSettings, outManifold);
    if (a == Capsule && b == Capsule)
        return CollideCapsuleCapsule(static_cast<const CapsuleShape&>(inA), inTransformA,
                                     static_cast<const CapsuleShape&>(inB), inTransformB, inSettings,
                                     outManifold);
    if (a == Box && b == Box)
        return CollideBoxBox(static_cast<const BoxShape&>(inA), inTransformA,
                             static_cast<const BoxShape&>(inB), inTransformB, inSettings, outManifold);
    return CollideConvexConvex(inA, inTransformA, inB, inTransformB, inSettings, outManifold);
}

} // namespace

int CollideShapes(const Shape& inShapeA, const Transform& inTransformA, const Shape& inShapeB,
                  const Transform& inTransformB, const CollideSettings& inSettings, ManifoldVisitor inVisitor)
{
    const ShapeType a = inShapeA.GetType();
    const ShapeType b = inShapeB.GetType();

    if (a == ShapeType::Compound || b == ShapeType::Compound)
    {
        // Recurse into the compound side (A first); each child's manifolds are tagged with its index and keep
        // the child's own id (a mesh child's triangle) above it, so that they keep distinct cache keys
        const bool splitA = a == ShapeType::Compound;
        const CompoundShape& compound = static_cast<const CompoundShape&>(splitA ? inShapeA : inShapeB);
        const Transform& compoundTransform = splitA ? inTransformA : inTransformB;
        const Shape& other = splitA ? inShapeB : inShapeA;
        const Transform& otherTransform = splitA ? inTransformB : inTransformA;
        const AABB otherBounds = other.GetWorldBounds(otherTransform).Expanded(inSettings.mMaxSeparation);
        int count = 0;
        const auto children = compound.GetSubShapes();
        for (size_t i = 0; i < children.size(); ++i)
        {
            const Transform childTransform = compoundTransform * children[i].mLocalTransform;
            if (!children[i].mShape->GetWorldBounds(childTransform).Overlaps(otherBounds)) continue;
            const auto tag = [&](const ContactManifold& inManifold)
            {
                ContactManifold m = inManifold;
                SubShapeID& id = splitA ? m.mSubShapeA : m.mSubShapeB;
                id = CompoundShape::MakeManifoldSubShapeID(uint32_t(i), children.size(), id);
                inVisitor(m);
            };
            count += splitA ? CollideShapes(*children[i].mShape, childTransform, other, otherTransform,
                                            inSettings, tag)
                            : CollideShapes(other, otherTransform, *children[i].mShape, childTransform,
                                            inSettings, tag);
        }
        return count;
    }

    if (IsTriangleSoup(a) && IsTriangleSoup(b)) return 0; // Neither can move: nothing to solve
    if (IsTriangleSoup(b))
    {
        if (!inShapeA.IsConvex()) return 0;
        return CollideConvexTriangles(static_cast<const ConvexShape&>(inShapeA), inTransformA, inShapeB,
                                      inTransformB, inSettings, inVisitor);
    }
    if (IsTriangleSoup(a))
    {
        if (!inShapeB.IsConvex()) return 0;
        const auto flip = [&](const ContactManifold& inManifold)
        {
            ContactManifold m = inManifold;
            FlipManifold(m);
            inVisitor(m);
        };
        return CollideConvexTriangles(static_cast<const ConvexShape&>(inShapeB), inTransformB, inShapeA,
                                      inTransformA, inSettings, flip);
    }

    if (!inShapeA.IsConvex() || !inShapeB.IsConvex()) return 0;
    ContactManifold m;
    if (!CollideConvexPair(static_cast<const ConvexShape&>(inShapeA), inTransformA,
                           static_cast<const ConvexShape&>(inShapeB), inTransformB, inSettings, m))
        return 0;
    if (m.mNumPoints == 0 || MaxPenetration(m) < -inSettings.mMaxSeparation) return 0;
    m.mSubShapeA = 0;
    m.mSubShapeB = 0;
    inVisitor(m);
    return 1;
}

} // namespace cairn::physics
