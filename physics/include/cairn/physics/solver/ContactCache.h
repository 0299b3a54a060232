#pragma once

// ContactCache: remembers each manifold's accumulated impulses from one step to the next, so the solver can
// warm-start. Keyed by (body A, body B, sub-shape A, sub-shape B); points are matched by their position on
// body A (within cPointMatchDistance). Two flat arrays are swapped each step and reused, so a warm scene
// allocates nothing. Physics step only (one thread): no locks.

#include "cairn/physics/body/BodyID.h"
#include "cairn/physics/narrowphase/ContactManifold.h"

#include <vector>

namespace cairn
{

struct ContactKey
{
    BodyID mBodyA;
    BodyID mBodyB;
    SubShapeID mSubShapeA;
    SubShapeID mSubShapeB;
    auto operator<=>(const ContactKey&) const = default;
};

struct CachedManifold
{
    ContactKey mKey;
    int mNumPoints = 0;
    Vec3 mLocalOnA[ContactManifold::cMaxPoints]; ///< In A's centre-of-mass frame
    float mNormalImpulse[ContactManifold::cMaxPoints];
    float mDeferredBounce[ContactManifold::cMaxPoints]; ///< Approach velocity of a bounce that happens next
                                                        ///< step
    Vec3 mFrictionImpulse =
        Vec3::Zero();           ///< Patch friction as a world vector, so a new tangent basis can take it over
    float mTwistImpulse = 0.0f; ///< Patch twist friction about the normal
};

class ContactCache
{
public:
    /// Points closer than this on body A from one step to the next are the same contact.
    static constexpr float cPointMatchDistance = 0.01f;

    /// Makes the manifolds of the step that just ended the ones to warm-start from.
    void BeginStep();
    /// Last step's manifold for inKey, or nullptr.
    const CachedManifold* FindPrevious(const ContactKey& inKey) const;
    /// Stores a manifold of this step; returns its index for Get().
    uint32_t Add(const CachedManifold& inManifold);
    CachedManifold& Get(uint32_t inIndex) { return mCurrent[inIndex]; }
    /// Sorts this step's manifolds for lookup next step. Indices from Add() are invalid afterwards.
    void EndStep();
    size_t GetNumManifolds() const { return mCurrent.size(); }
    void Clear();

private:
    std::vector<CachedManifold> mPrevious; ///< Sorted by key
    std::vector<CachedManifold> mCurrent;  ///< In creation order until EndStep
};

} // namespace cairn
