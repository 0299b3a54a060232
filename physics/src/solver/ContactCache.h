#pragma once

// ContactCache: remembers each manifold's accumulated impulses from one step to the next, so the solver can
// warm-start. Keyed by (body A, body B, sub-shape A, sub-shape B); points of a newly collided manifold are
// matched by their position on body A (within cPointMatchDistance), those of a manifold taken over one for
// one. It also remembers each body pair the narrow phase saw, with the pose
// of B relative to A when its manifolds were made, so that a pair that has not moved relative to itself takes
// its manifolds over without colliding the shapes again (a resting pile is most of a game's pairs).
// Flat arrays are swapped each step and reused, so a warm scene allocates nothing. Sized by the physics
// step's updating thread only (Add, AddPair, Append*, EndStep); the slots that Append* makes room for may
// then be filled by the step's worker threads, each its own, before the updating thread goes on (the job
// system's wait orders the writes); so may the impulses of this step's manifolds (through Get), each island's
// by the thread that solves it. The narrow phase's threads read the previous step's arrays, which
// nothing writes until the next BeginStep: no locks.

#include "cairn/physics/body/BodyID.h"
#include "cairn/physics/narrowphase/ContactManifold.h"
#include "math/UninitializedAllocator.h"

#include <span>
#include <type_traits>
#include <utility>
#include <vector>

namespace cairn::physics
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
    Vec3 mNormalOnA = Vec3::UnitY();             ///< The manifold's normal in A's rotation frame
    Vec3 mLocalOnA[ContactManifold::cMaxPoints]; ///< In A's centre-of-mass frame
    Vec3 mLocalOnB[ContactManifold::cMaxPoints]; ///< In B's centre-of-mass frame
    float mNormalImpulse[ContactManifold::cMaxPoints];
    Vec3 mFrictionImpulse =
        Vec3::Zero();           ///< Patch friction as a world vector, so a new tangent basis can take it over
    float mTwistImpulse = 0.0f; ///< Patch twist friction about the normal
};

/// A pair of bodies the narrow phase collided, and the manifolds it found (perhaps none).
struct CachedBodyPair
{
    BodyID mBodyA;
    BodyID mBodyB;
    Vec3 mDeltaPosition;         ///< B's centre of mass minus A's, in A's frame, when the manifolds were made
    Quat mDeltaRotation;         ///< conjugate(A's rotation) * B's rotation, then
    float mMaxSeparation;        ///< How far apart the shapes could be and still make contact points, then
    uint32_t mFirstManifold = 0; ///< Into the same step's manifolds (valid after EndStep)
    uint32_t mNumManifolds = 0;
    /// The bodies' Body::mShapeGeneration then: a new shape at the same pose is collided again. In what was
    /// padding (the record stays 64 bytes)
    uint16_t mShapeGenerationA = 0;
    uint16_t mShapeGenerationB = 0;
};
static_assert(sizeof(CachedBodyPair) == 64, "one cache line");

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
    /// Makes room for inCount more manifolds of this step and returns the first's index. They are unset: the
    /// caller must fill each (through Get) before EndStep.
    uint32_t AppendManifolds(uint32_t inCount)
    {
        const size_t first = mCurrent.size();
        mCurrent.resize(first + inCount);
        return uint32_t(first);
    }
    /// Last step's record of the pair (A, B), or nullptr. ioHint (optional, start at 0): where the previous
    /// lookup of this caller ended; lookups in increasing pair order then cost a few steps instead of a
    /// binary search of the whole array. Any value gives the right answer.
    const CachedBodyPair* FindPreviousPair(BodyID inBodyA, BodyID inBodyB, uint32_t* ioHint = nullptr) const;
    /// Last step's manifolds of a pair from FindPreviousPair.
    std::span<const CachedManifold> GetPreviousManifolds(const CachedBodyPair& inPair) const
    {
        return {mPrevious.data() + inPair.mFirstManifold, inPair.mNumManifolds};
    }
    /// Last step's manifolds, all of them, in key order (between BeginStep and the next one).
    std::span<const CachedManifold> GetAllPreviousManifolds() const { return mPrevious; }
    /// This step's manifolds: in key order after EndStep.
    std::span<const CachedManifold> GetManifolds() const { return mCurrent; }
    /// Stores a body pair of this step: its manifolds are the next inPair.mNumManifolds given to Add().
    void AddPair(const CachedBodyPair& inPair) { mCurrentPairs.push_back(inPair); }
    /// Makes room for inCount more body pairs of this step (unset: each to be filled through GetPair) and
    /// returns the first's index. Their manifolds are those in the same places of the manifolds appended, as
    /// with AddPair.
    uint32_t AppendPairs(uint32_t inCount)
    {
        const size_t first = mCurrentPairs.size();
        mCurrentPairs.resize(first + inCount);
        return uint32_t(first);
    }
    CachedBodyPair& GetPair(uint32_t inIndex) { return mCurrentPairs[inIndex]; }
    /// Sorts this step's manifolds and pairs for lookup next step. Indices from Add() are invalid afterwards.
    /// inInOrder: the caller knows that both are in key order already (no entry before the one before it)
    /// and has set each pair's mFirstManifold (the narrow phase's merge does both in parallel): then nothing
    /// is left to do. Otherwise they are checked, sorted if need be, and the pairs' manifolds found.
    void EndStep(bool inInOrder = false);
    size_t GetNumManifolds() const { return mCurrent.size(); }
    /// After EndStep: whether this step's manifolds and pairs are in strictly increasing key order and each
    /// pair's manifolds are where its mFirstManifold says, one after another (what next step's lookups rely
    /// on). A self-check for tests: O(n).
    bool IsConsistent() const;
    void Clear();

private:
    // Grown by Append* and then filled: the growth writes nothing (see UninitializedAllocator)
    static_assert(std::is_aggregate_v<CachedManifold> && std::is_trivially_destructible_v<CachedManifold> &&
                      std::is_aggregate_v<CachedBodyPair> && std::is_trivially_destructible_v<CachedBodyPair>,
                  "implicit-lifetime types: Append* leaves their bytes unset");
    using Manifolds = std::vector<CachedManifold, UninitializedAllocator<CachedManifold>>;
    using Pairs = std::vector<CachedBodyPair, UninitializedAllocator<CachedBodyPair>>;
    Manifolds mPrevious;  ///< Sorted by key
    Manifolds mCurrent;   ///< In creation order until EndStep
    Pairs mPreviousPairs; ///< Sorted by bodies, each with its manifolds in mPrevious
    Pairs mCurrentPairs;  ///< In creation order until EndStep
    Manifolds mScratch;   ///< EndStep's sorting buffers, kept for their capacity
    Pairs mScratchPairs;
    std::vector<std::pair<ContactKey, uint32_t>> mManifoldOrder;
    std::vector<std::pair<std::pair<BodyID, BodyID>, uint32_t>> mPairOrder;
};

} // namespace cairn::physics
