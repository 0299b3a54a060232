#pragma once

// One body pair's manifolds, merged where their normals agree: a convex shape lying across two or three
// triangles of a gently curved height field or mesh gets one manifold (one friction patch, at most four
// points) instead of one per triangle, as Jolt's manifold reduction does. The solver then pushes once per
// surface instead of once per triangle under it, and the narrow phase, the contact cache and the solver each
// handle fewer manifolds.
//
// Greedy, in the order the manifolds come (the triangles' order, so the result is deterministic): a manifold
// joins the first group whose first normal is within cMergeNormalCos of its own, else starts a group. A
// group's normal is the normalized sum of its members' normals; its points are re-measured along it, points
// that two triangles both report at one place (a shared edge) are kept once, and ReduceContactPoints keeps
// four. A group keeps its first manifold's sub-shapes, which key its warm start.
//
// Threads: one per pair, on the stack of the thread that collides the pair.

#include "cairn/physics/narrowphase/ContactManifold.h"

namespace cairn::physics
{

class ManifoldMerger
{
public:
    /// cos(5 degrees): the tolerance of Jolt's PhysicsSettings::mContactNormalCosMaxDeltaRotation.
    static constexpr float cMergeNormalCos = 0.9961947f;
    /// Groups kept at once; a manifold that fits none when all are taken is passed on unmerged.
    static constexpr int cMaxGroups = 4;
    /// Points a group collects before they are reduced to ContactManifold::cMaxPoints.
    static constexpr int cMaxGroupPoints = 16;
    /// Two points of one group closer than this (on both bodies) are one point reported twice.
    static constexpr float cSamePointDistance = 1.0e-3f;

    /// Adds one manifold of the pair. Returns false when it could not be kept (every group taken by other
    /// normals): the caller uses it as it is.
    bool Add(const ContactManifold& inManifold);
    /// The merged manifolds, in the order their groups started; inVisit(const ContactManifold&).
    template <class Visit> void ForEach(Visit&& inVisit) const
    {
        ContactManifold out;
        for (int g = 0; g < mNumGroups; ++g)
        {
            Finish(mGroups[g], out);
            inVisit(static_cast<const ContactManifold&>(out));
        }
    }
    int GetNumGroups() const { return mNumGroups; }

private:
    /// Plain fields only: a merger is made for every pair with a mesh, height field or compound, so its
    /// construction must not write its groups
    struct Group
    {
        Vec3 mFirstNormal; ///< The normal a manifold must be close to, to join
        Vec3 mNormalSum;
        SubShapeID mSubShapeA; ///< The first manifold's: they key the warm start
        SubShapeID mSubShapeB;
        int mNumMerged;
        int mNumPoints;
        ContactPoint mPoints[cMaxGroupPoints];
    };
    static void AddPoints(Group& ioGroup, const ContactManifold& inManifold);
    /// Reduces a full point list to four along the group's current normal, making room for more.
    static void Compact(Group& ioGroup);
    static void Finish(const Group& inGroup, ContactManifold& outManifold);

    Group mGroups[cMaxGroups];
    int mNumGroups = 0;
};

} // namespace cairn::physics
