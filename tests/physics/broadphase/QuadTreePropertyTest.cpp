// BroadPhaseQuadTree against the brute-force oracle, as a rapidcheck property: for any sequence of operations
// on a pool of 10,000 body ids, every query kind and FindCollidingPairs return exactly the set that
// BroadPhaseBruteForce returns.
//
// rapidcheck generates the operation list: add batches, aborted batches, batches prepared early and
// finalized or aborted several operations later (other adds, removes, moves and rebuilds in between), removes
// (with stale, absent and repeated ids, which both must ignore), small moves that stay inside their slot,
// jumps across the world, object-layer changes between Static, Moving, Debris and Trigger (some move a body
// to the other broad-phase layer's tree, some only change its layer inside the tree), Update() and
// RebuildAll(). Removed bodies come back with the same id or a new sequence number. After every operation,
// random box, sphere, point, ray and swept-box queries (each cast with a visitor that takes every hit, one
// that keeps the closest hit and one that stops at the first), under random object-layer filters, and a
// FindCollidingPairs over a random active subset (sometimes with a random collision table) are compared as
// sorted vectors, ray fractions included, element by element; the quad tree must also pass Validate() and
// count the same bodies. Coordinates sit on a 0.5 m grid half of the time and queries are aimed at body
// corners and faces, so touching, grazing and axis-parallel cases are common.
//
// Why: the quad tree's slot bounds only grow between rebuilds, a rebuild keeps unchanged sub-trees, batches
// are built off the live tree and linked in O(1), and a layer change moves a body between trees. Its queries
// must still report exactly the bodies whose current AABB matches (the engine relies on the broad phases
// agreeing bit for bit), which only a comparison with an obviously correct oracle over arbitrary histories
// shows. On a difference rapidcheck shrinks the history to a minimal one and prints it with the first
// difference. One property uses worlds of up to a few thousand bodies and many cases; another starts every
// case with all 10,000 bodies. A last test runs the property against deliberately broken broad phases and
// requires it to fail, so a property that can no longer see differences does not pass silently.
// Everything runs on one thread: this checks the sequential semantics, not the lock-free interleavings.

#include "broadphase/BroadPhaseBruteForce.h"
#include "broadphase/BroadPhaseQuadTree.h"
#include "common/TestRandom.h"

#include <algorithm>
#include <cmath>
#include <concepts>
#include <gtest/gtest.h>
#include <iomanip>
#include <memory>
#include <ostream>
#include <rapidcheck/gtest.h>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace cairn
{
using namespace cairn::physics;
namespace
{

/// Body indices are below this; the 10,000-body property adds all of them.
constexpr uint32_t cPoolSize = 10000;
/// Batches that may be prepared and not yet finalized or aborted at the same time.
constexpr size_t cMaxPendingBatches = 3;

enum class OpKind : uint8_t
{
    Update,          ///< Update() (rebuild of the changed parts)
    RebuildAll,      ///< RebuildAll() (the oracle: Update())
    AddBatch,        ///< Prepare and finalize a batch of absent bodies
    AbortBatch,      ///< Prepare and abort a batch: nothing may appear
    PrepareDeferred, ///< Prepare a batch now; FinishDeferred finalizes or aborts it later
    FinishDeferred,  ///< Finalize or abort one of the deferred batches
    Remove,          ///< Remove present bodies, mixed with stale, absent and repeated ids
    MoveSmall,       ///< Small moves and resizes (usually inside the slot)
    MoveLarge,       ///< Jumps anywhere in the world
    ChangeLayer      ///< New object layer (maybe another broad-phase layer), sometimes with a small move
};

const char* ToString(OpKind inKind)
{
    switch (inKind)
    {
    case OpKind::Update:
        return "Update";
    case OpKind::RebuildAll:
        return "RebuildAll";
    case OpKind::AddBatch:
        return "AddBatch";
    case OpKind::AbortBatch:
        return "AbortBatch";
    case OpKind::PrepareDeferred:
        return "PrepareDeferred";
    case OpKind::FinishDeferred:
        return "FinishDeferred";
    case OpKind::Remove:
        return "Remove";
    case OpKind::MoveSmall:
        return "MoveSmall";
    case OpKind::MoveLarge:
        return "MoveLarge";
    case OpKind::ChangeLayer:
        return "ChangeLayer";
    }
    return "?";
}

/// One generated operation. The seed drives its details (which bodies, new bounds and layers) and the
/// queries that follow it, so that a shrunk operation list replays exactly.
struct Op
{
    OpKind mKind = OpKind::Update;
    uint32_t mCount = 0; ///< Bodies to add, remove or move (fewer when not enough are available)
    uint32_t mSeed = 0;
};

std::ostream& operator<<(std::ostream& ioStream, const Op& inOp)
{
    return ioStream << ToString(inOp.mKind) << "(count " << inOp.mCount << ", seed " << inOp.mSeed << ")";
}

/// The world of one generated case.
struct Scenario
{
    float mExtent = 250.0f;       ///< Bodies lie in [0, extent] in x and z
    uint32_t mInitialBodies = 0;  ///< Added before the operations...
    uint32_t mInitialBatches = 1; ///< ...in this many batches
    uint32_t mSeed = 0;           ///< Initial bodies and the first queries
    uint32_t mMaxActive = 300;    ///< Cap on the active list given to FindCollidingPairs
    int mQueries = 6;             ///< Random queries of each kind after every operation
};

std::ostream& operator<<(std::ostream& ioStream, const Scenario& inScenario)
{
    return ioStream << "Scenario(extent " << inScenario.mExtent << ", " << inScenario.mInitialBodies
                    << " initial bodies in " << inScenario.mInitialBatches << " batches, seed "
                    << inScenario.mSeed << ", max active " << inScenario.mMaxActive << ", "
                    << inScenario.mQueries << " queries of each kind per check)";
}

/// Random bodies and queries for a world of mExtent x height x mExtent; a coordinate is on the 0.5 m grid
/// half of the time (TestRandom::Coordinate), so that faces, edges and corners coincide often.
class WorldRandom : public test::TestRandom
{
public:
    WorldRandom(uint32_t inSeed, float inExtent)
        : TestRandom(inSeed), mExtent(inExtent), mHeight(std::max(10.0f, 0.24f * inExtent))
    {
    }

    /// A point in or just around the world.
    Vec3 Position()
    {
        return {Coordinate(-2.0f, mExtent + 2.0f), Coordinate(-5.0f, mHeight - 5.0f),
                Coordinate(-2.0f, mExtent + 2.0f)};
    }

    /// Bounds of mixed sizes: points, flat boxes, small and medium boxes and a few wide slabs.
    AABB Bounds()
    {
        const Vec3 min(Coordinate(0.0f, mExtent), Coordinate(-5.0f, mHeight - 5.0f),
                       Coordinate(0.0f, mExtent));
        const float kind = Uniform(0.0f, 1.0f);
        Vec3 size;
        if (kind < 0.03f)
            size = Vec3::Zero();
        else if (kind < 0.06f)
        {
            size = Vec3(Coordinate(0.1f, 4.0f), Coordinate(0.1f, 4.0f), Coordinate(0.1f, 4.0f));
            size[int(Index(3))] = 0.0f;
        }
        else if (kind < 0.08f)
            size = Vec3(Uniform(0.1f, 0.35f) * mExtent, Uniform(0.5f, 2.0f), Uniform(0.1f, 0.35f) * mExtent);
        else if (kind < 0.9f)
            size = Vec3(Coordinate(0.1f, 3.0f), Coordinate(0.1f, 3.0f), Coordinate(0.1f, 3.0f));
        else
            size = Vec3(Coordinate(3.0f, 10.0f), Coordinate(0.5f, 10.0f), Coordinate(3.0f, 10.0f));
        return {min, min + size};
    }

    /// Static and moving bodies mostly, then debris and a few triggers.
    ObjectLayer Layer()
    {
        const float kind = Uniform(0.0f, 1.0f);
        if (kind < 0.35f) return Layers::cStatic;
        if (kind < 0.7f) return Layers::cMoving;
        if (kind < 0.9f) return Layers::cDebris;
        return Layers::cTrigger;
    }

    /// A query filter: all layers, a subset of the four, one layer, or random bits (beyond the four too).
    ObjectLayerMask Mask()
    {
        const float kind = Uniform(0.0f, 1.0f);
        if (kind < 0.5f) return cAllObjectLayers;
        if (kind < 0.8f) return ObjectLayerMask(Index(16));
        if (kind < 0.9f) return ObjectLayerMask(1) << Index(4);
        return (ObjectLayerMask(mRandom()) << 32) | ObjectLayerMask(mRandom());
    }

    /// A ray or sweep displacement: random, along one axis (through faces and along slab planes), exactly to
    /// a grid point, or zero. Zero components are sometimes negative zero (an infinity of the other sign in
    /// the slab test).
    Vec3 Displacement(const Vec3& inFrom)
    {
        Vec3 displacement;
        const float kind = Uniform(0.0f, 1.0f);
        if (kind < 0.4f)
            displacement = Vec3(Uniform(-60.0f, 60.0f), Uniform(-20.0f, 20.0f), Uniform(-60.0f, 60.0f));
        else if (kind < 0.75f)
        {
            displacement = Vec3::Zero();
            displacement[int(Index(3))] = (Chance(0.5f) ? 1.0f : -1.0f) * Coordinate(0.5f, 80.0f);
        }
        else if (kind < 0.97f)
            displacement = Position() - inFrom;
        else
            displacement = Vec3::Zero();
        for (int axis = 0; axis < 3; ++axis)
            if (displacement[axis] == 0.0f && Chance(0.3f)) displacement[axis] = -0.0f;
        return displacement;
    }

    float mExtent; ///< Size of the world in x and z
    float mHeight; ///< Size of the world in y (from -5)
};

/// A set of body indices with O(1) insert, erase and random pick.
class IndexSet
{
public:
    explicit IndexSet(uint32_t inCapacity) : mPosition(inCapacity, cNone) {}

    bool Contains(uint32_t inIndex) const { return mPosition[inIndex] != cNone; }
    bool Empty() const { return mItems.empty(); }
    size_t Size() const { return mItems.size(); }
    const std::vector<uint32_t>& Items() const { return mItems; }
    uint32_t Pick(test::TestRandom& ioRandom) const
    {
        return mItems[ioRandom.Index(uint32_t(mItems.size()))];
    }

    void Insert(uint32_t inIndex)
    {
        if (Contains(inIndex)) return;
        mPosition[inIndex] = uint32_t(mItems.size());
        mItems.push_back(inIndex);
    }
    void Erase(uint32_t inIndex)
    {
        const uint32_t position = mPosition[inIndex];
        if (position == cNone) return;
        const uint32_t last = mItems.back();
        mItems[position] = last;
        mPosition[last] = position;
        mItems.pop_back();
        mPosition[inIndex] = cNone;
    }

private:
    static constexpr uint32_t cNone = 0xffffffffu;
    std::vector<uint32_t> mItems;    ///< Unordered
    std::vector<uint32_t> mPosition; ///< Index -> position in mItems, or cNone
};

// Results of the queries, as sorted vectors so that both broad phases can be compared element by element

using HitList = std::vector<BodyID>;
using RayHitList = std::vector<std::pair<BodyID, float>>;
using PairList = std::vector<std::pair<BodyID, BodyID>>;

void Print(std::ostream& ioStream, BodyID inID)
{
    ioStream << "#" << inID.GetIndex() << "/" << inID.GetSequence();
}
void Print(std::ostream& ioStream, const std::pair<BodyID, float>& inHit)
{
    Print(ioStream, inHit.first);
    ioStream << "@" << std::setprecision(9) << inHit.second;
}
void Print(std::ostream& ioStream, const std::pair<BodyID, BodyID>& inPair)
{
    ioStream << "(";
    Print(ioStream, inPair.first);
    ioStream << ", ";
    Print(ioStream, inPair.second);
    ioStream << ")";
}
std::string ToString(const Vec3& inV)
{
    std::ostringstream stream;
    stream << std::setprecision(9) << "(" << inV.x() << ", " << inV.y() << ", " << inV.z() << ")";
    return stream.str();
}
std::string ToString(const AABB& inBox)
{
    // A stream, not "[" + ...: inlined into a unity build's batch, that chain meets a false
    // -Wstringop-overflow in GCC 12's std::string
    std::ostringstream stream;
    stream << "[" << ToString(inBox.mMin) << " - " << ToString(inBox.mMax) << "]";
    return stream.str();
}
std::string MaskToString(ObjectLayerMask inMask)
{
    std::ostringstream stream;
    stream << "mask 0x" << std::hex << inMask;
    return stream.str();
}

/// Empty when both sorted lists are equal, else what differs (at most 8 elements of each side).
template <class T>
std::string DescribeDifference(const std::vector<T>& inOracle, const std::vector<T>& inTested)
{
    if (inOracle == inTested) return {};
    std::vector<T> onlyOracle;
    std::vector<T> onlyTested;
    std::set_difference(inOracle.begin(), inOracle.end(), inTested.begin(), inTested.end(),
                        std::back_inserter(onlyOracle));
    std::set_difference(inTested.begin(), inTested.end(), inOracle.begin(), inOracle.end(),
                        std::back_inserter(onlyTested));
    std::ostringstream stream;
    auto printSome = [&](const std::vector<T>& inList)
    {
        for (size_t i = 0; i < std::min<size_t>(inList.size(), 8); ++i)
        {
            stream << " ";
            Print(stream, inList[i]);
        }
        if (inList.size() > 8) stream << " ...";
    };
    stream << "brute force reports " << inOracle.size() << ", quad tree " << inTested.size()
           << "; only brute force (" << onlyOracle.size() << "):";
    printSome(onlyOracle);
    stream << "; only quad tree (" << onlyTested.size() << "):";
    printSome(onlyTested);
    return stream.str();
}

template <class T> std::vector<T> Sorted(std::vector<T> inList)
{
    std::sort(inList.begin(), inList.end());
    return inList;
}

HitList BoxHits(const BroadPhase& inBroadPhase, const AABB& inBox, ObjectLayerMask inMask)
{
    HitList hits;
    inBroadPhase.CollideAABox(inBox, {inMask}, [&](BodyID inID) { hits.push_back(inID); });
    return Sorted(std::move(hits));
}
HitList SphereHits(const BroadPhase& inBroadPhase, const Vec3& inCenter, float inRadius,
                   ObjectLayerMask inMask)
{
    HitList hits;
    inBroadPhase.CollideSphere(inCenter, inRadius, {inMask}, [&](BodyID inID) { hits.push_back(inID); });
    return Sorted(std::move(hits));
}
HitList PointHits(const BroadPhase& inBroadPhase, const Vec3& inPoint, ObjectLayerMask inMask)
{
    HitList hits;
    inBroadPhase.CollidePoint(inPoint, {inMask}, [&](BodyID inID) { hits.push_back(inID); });
    return Sorted(std::move(hits));
}

/// A cast (ray or swept box) of one broad phase with a given visitor.
using CastFunction = FunctionRef<void(const BroadPhase& inBroadPhase, RayBodyVisitor inVisitor)>;

/// Every body on the cast with its entry fraction (the visitor keeps the maximum at 1).
RayHitList AllCastHits(const BroadPhase& inBroadPhase, CastFunction inCast)
{
    RayHitList hits;
    inCast(inBroadPhase,
           [&](BodyID inID, float inFraction)
           {
               hits.emplace_back(inID, inFraction);
               return 1.0f;
           });
    return Sorted(std::move(hits));
}

/// Closest hit: the visitor prunes with every fraction it gets; returns the bodies reported at the smallest
/// fraction (each broad phase must report every body entered at that fraction, whatever its order).
RayHitList ClosestCastHits(const BroadPhase& inBroadPhase, CastFunction inCast)
{
    RayHitList reported;
    inCast(inBroadPhase,
           [&](BodyID inID, float inFraction)
           {
               reported.emplace_back(inID, inFraction);
               return inFraction;
           });
    float closest = 2.0f;
    for (const auto& hit : reported)
        closest = std::min(closest, hit.second);
    RayHitList atClosest;
    for (const auto& hit : reported)
        if (hit.second == closest) atClosest.push_back(hit);
    return Sorted(std::move(atClosest));
}

/// Visitor calls when the visitor stops the cast at once (must be 1 when anything is hit, else 0).
size_t CallsWhenStopped(const BroadPhase& inBroadPhase, CastFunction inCast)
{
    size_t calls = 0;
    inCast(inBroadPhase,
           [&](BodyID, float)
           {
               ++calls;
               return -1.0f;
           });
    return calls;
}

/// Compares all three visitors of a cast; empty when equal.
std::string CompareCast(const BroadPhase& inOracle, const BroadPhase& inTested, CastFunction inCast,
                        size_t& ioHits)
{
    const RayHitList all = AllCastHits(inOracle, inCast);
    ioHits += all.size();
    if (std::string difference = DescribeDifference(all, AllCastHits(inTested, inCast)); !difference.empty())
        return "all hits: " + difference;
    if (std::string difference =
            DescribeDifference(ClosestCastHits(inOracle, inCast), ClosestCastHits(inTested, inCast));
        !difference.empty())
        return "closest hits: " + difference;
    const size_t expectedCalls = all.empty() ? 0 : 1;
    if (const size_t calls = CallsWhenStopped(inTested, inCast); calls != expectedCalls)
        return "stopping visitor called " + std::to_string(calls) + " times by the quad tree, expected " +
               std::to_string(expectedCalls);
    return {};
}

PairList CollidingPairs(const BroadPhase& inBroadPhase, std::span<const BodyID> inActive,
                        const LayerSetup& inLayers)
{
    PairList pairs;
    inBroadPhase.FindCollidingPairs(inActive, inLayers,
                                    [&](BodyID inA, BodyID inB) { pairs.emplace_back(inA, inB); });
    return Sorted(std::move(pairs));
}

/// What the property needs of the tested broad phase beyond the BroadPhase interface.
template <class T>
concept TestedBroadPhase = std::derived_from<T, BroadPhase> && requires(T& ioTested, const T& inTested)
{
    ioTested.RebuildAll();
    {
        inTested.Validate()
        } -> std::same_as<bool>;
};

/// Applies operations to the oracle and the tested broad phase and compares them. Keeps the model: which body
/// indices are present, absent or in a prepared batch, each index's current id and what was stored for it.
template <TestedBroadPhase Tested> class Harness
{
public:
    Harness(const Scenario& inScenario, Tested& ioTested)
        : mScenario(inScenario), mTested(ioTested), mLayers(LayerSetup::CreateDefault()),
          mSequence(cPoolSize, 1), mStored(cPoolSize), mPresent(cPoolSize), mAbsent(cPoolSize),
          mPendingIndex(cPoolSize, 0)
    {
        for (uint32_t index = 0; index < cPoolSize; ++index)
            mAbsent.Insert(index);
    }
    /// Aborts batches still prepared (a failed check leaves the case early), so nothing leaks.
    ~Harness()
    {
        for (const std::unique_ptr<PendingBatch>& batch : mPending)
        {
            mOracle.AddBodiesAbort(batch->mOracleState);
            mTested.AddBodiesAbort(batch->mTestedState);
        }
    }
    Harness(const Harness&) = delete;
    Harness& operator=(const Harness&) = delete;

    /// Adds the scenario's initial bodies in its number of batches.
    void Fill()
    {
        WorldRandom random(mScenario.mSeed, mScenario.mExtent);
        const uint32_t batches = std::max(1u, mScenario.mInitialBatches);
        for (uint32_t b = 0; b < batches; ++b)
        {
            const uint32_t count =
                mScenario.mInitialBodies / batches + (b == 0 ? mScenario.mInitialBodies % batches : 0);
            const std::vector<BroadPhaseBody> batch = TakeAbsent(random, count);
            mOracle.AddBodiesFinalize(mOracle.AddBodiesPrepare(batch));
            mTested.AddBodiesFinalize(mTested.AddBodiesPrepare(batch));
            MarkPresent(batch);
        }
    }

    void Apply(const Op& inOp)
    {
        WorldRandom random(inOp.mSeed, mScenario.mExtent);
        switch (inOp.mKind)
        {
        case OpKind::Update:
            mOracle.Update();
            mTested.Update();
            break;
        case OpKind::RebuildAll:
            mOracle.Update();
            mTested.RebuildAll();
            break;
        case OpKind::AddBatch:
        case OpKind::AbortBatch:
        {
            const std::vector<BroadPhaseBody> batch = TakeAbsent(random, inOp.mCount);
            BroadPhase::AddState oracleState = mOracle.AddBodiesPrepare(batch);
            BroadPhase::AddState testedState = mTested.AddBodiesPrepare(batch);
            if (inOp.mKind == OpKind::AddBatch)
            {
                mOracle.AddBodiesFinalize(oracleState);
                mTested.AddBodiesFinalize(testedState);
                MarkPresent(batch);
            }
            else
            {
                mOracle.AddBodiesAbort(oracleState);
                mTested.AddBodiesAbort(testedState);
                MarkAbsent(batch);
            }
            break;
        }
        case OpKind::PrepareDeferred:
        {
            if (mPending.size() >= cMaxPendingBatches) break;
            auto batch = std::make_unique<PendingBatch>();
            batch->mBodies = TakeAbsent(random, inOp.mCount);
            for (const BroadPhaseBody& body : batch->mBodies)
                mPendingIndex[body.mID.GetIndex()] = 1;
            batch->mOracleState = mOracle.AddBodiesPrepare(batch->mBodies);
            batch->mTestedState = mTested.AddBodiesPrepare(batch->mBodies);
            mPending.push_back(std::move(batch));
            break;
        }
        case OpKind::FinishDeferred:
            if (!mPending.empty())
                FinishPending(random.Index(uint32_t(mPending.size())), random.Chance(0.7f));
            break;
        case OpKind::Remove:
            Remove(random, inOp.mCount);
            break;
        case OpKind::MoveSmall:
        case OpKind::MoveLarge:
        case OpKind::ChangeLayer:
            Move(random, inOp.mKind, inOp.mCount);
            break;
        }
    }

    /// Finalizes every batch still prepared, oldest first.
    void FinishAllPending()
    {
        while (!mPending.empty())
            FinishPending(0, true);
    }

    /// Compares the broad phases: structure, count, mScenario.mQueries queries of each kind and one pair
    /// search, all drawn from inSeed. Fails the rapidcheck case with inWhen and the first difference.
    void Check(uint32_t inSeed, const std::string& inWhen)
    {
        RC_ASSERT(mTested.Validate());
        RC_ASSERT(mOracle.GetBodyCount() == mPresent.Size());
        RC_ASSERT(mTested.GetBodyCount() == mPresent.Size());

        WorldRandom random(inSeed ^ 0x9e3779b9u, mScenario.mExtent);
        for (int query = 0; query < mScenario.mQueries; ++query)
            if (const std::string difference = CompareQueries(random); !difference.empty())
                RC_FAIL(inWhen + ", query " + std::to_string(query) + ": " + difference);
        if (const std::string difference = ComparePairs(random); !difference.empty())
            RC_FAIL(inWhen + ": " + difference);
    }

    /// Hits and pairs the oracle reported in all checks (so that a test can check they are not all empty).
    size_t GetTotalHits() const { return mTotalHits; }
    size_t GetTotalPairs() const { return mTotalPairs; }

    /// Runs one generated case: fill, then every operation followed by a check, then the pending batches and
    /// a last rebuild.
    void Run(const std::vector<Op>& inOps)
    {
        Fill();
        Check(mScenario.mSeed, "after the initial fill");
        for (size_t i = 0; i < inOps.size(); ++i)
        {
            Apply(inOps[i]);
            std::ostringstream when;
            when << "after operation " << i << " " << inOps[i];
            Check(inOps[i].mSeed, when.str());
        }
        if (!mPending.empty())
        {
            FinishAllPending();
            Check(mScenario.mSeed + 1, "after finalizing the deferred batches at the end");
        }
        mOracle.Update();
        mTested.Update();
        Check(mScenario.mSeed + 2, "after the final Update");
    }

private:
    /// A batch prepared by PrepareDeferred; the bodies stay valid (and unmoved) until it is finished.
    struct PendingBatch
    {
        std::vector<BroadPhaseBody> mBodies;
        BroadPhase::AddState mOracleState = nullptr;
        BroadPhase::AddState mTestedState = nullptr;
    };

    /// Up to inCount absent bodies with new bounds and layers, taken out of mAbsent. Half of them get a new
    /// sequence number (a new body in the slot), the others come back with their previous id.
    std::vector<BroadPhaseBody> TakeAbsent(WorldRandom& ioRandom, uint32_t inCount)
    {
        std::vector<BroadPhaseBody> batch;
        for (uint32_t i = 0; i < inCount && !mAbsent.Empty(); ++i)
        {
            const uint32_t index = mAbsent.Pick(ioRandom);
            mAbsent.Erase(index);
            if (ioRandom.Chance(0.5f)) ++mSequence[index];
            batch.push_back({BodyID(index, mSequence[index]), ioRandom.Bounds(), ioRandom.Layer()});
        }
        return batch;
    }
    void MarkPresent(std::span<const BroadPhaseBody> inBodies)
    {
        for (const BroadPhaseBody& body : inBodies)
        {
            mPendingIndex[body.mID.GetIndex()] = 0;
            mStored[body.mID.GetIndex()] = body;
            mPresent.Insert(body.mID.GetIndex());
        }
    }
    void MarkAbsent(std::span<const BroadPhaseBody> inBodies)
    {
        for (const BroadPhaseBody& body : inBodies)
        {
            mPendingIndex[body.mID.GetIndex()] = 0;
            mAbsent.Insert(body.mID.GetIndex());
        }
    }

    void FinishPending(size_t inBatch, bool inFinalize)
    {
        std::unique_ptr<PendingBatch> batch = std::move(mPending[inBatch]);
        mPending.erase(mPending.begin() + ptrdiff_t(inBatch));
        if (inFinalize)
        {
            mOracle.AddBodiesFinalize(batch->mOracleState);
            mTested.AddBodiesFinalize(batch->mTestedState);
            MarkPresent(batch->mBodies);
        }
        else
        {
            mOracle.AddBodiesAbort(batch->mOracleState);
            mTested.AddBodiesAbort(batch->mTestedState);
            MarkAbsent(batch->mBodies);
        }
    }

    /// An id that is not present: a present or absent index with another sequence number. Never an index of a
    /// prepared batch (its body is being added: the caller serialises that with any other operation on it).
    bool StaleID(WorldRandom& ioRandom, BodyID& outID) const
    {
        const uint32_t index = ioRandom.Index(cPoolSize);
        if (mPendingIndex[index] != 0) return false;
        outID = BodyID(index, mSequence[index] + 1 + ioRandom.Index(3));
        return true;
    }

    void Remove(WorldRandom& ioRandom, uint32_t inCount)
    {
        std::vector<BodyID> removed;
        for (uint32_t i = 0; i < inCount && !mPresent.Empty(); ++i)
        {
            const uint32_t index = mPresent.Pick(ioRandom);
            mPresent.Erase(index);
            mAbsent.Insert(index);
            removed.push_back(mStored[index].mID);
        }
        // Ids that are not present (ignored by both): stale ones and, now and then, one removed twice
        const uint32_t extra = inCount / 8 + (ioRandom.Chance(0.3f) ? 1 : 0);
        for (uint32_t i = 0; i < extra; ++i)
        {
            BodyID id;
            if (!removed.empty() && ioRandom.Chance(0.3f))
                removed.push_back(removed[ioRandom.Index(uint32_t(removed.size()))]);
            else if (StaleID(ioRandom, id))
                removed.push_back(id);
        }
        std::shuffle(removed.begin(), removed.end(), ioRandom.mRandom);
        mOracle.RemoveBodies(removed);
        mTested.RemoveBodies(removed);
    }

    void Move(WorldRandom& ioRandom, OpKind inKind, uint32_t inCount)
    {
        std::vector<BroadPhaseBody> moved;
        // The same body may be moved twice in one call: the last entry wins
        for (uint32_t i = 0; i < inCount && !mPresent.Empty(); ++i)
        {
            const uint32_t index = mPresent.Pick(ioRandom);
            BroadPhaseBody body = mStored[index];
            if (inKind == OpKind::MoveLarge)
            {
                if (ioRandom.Chance(0.8f))
                    body.mBounds = ioRandom.Bounds();
                else
                {
                    // A long jump of the same box, often by whole grid steps
                    const Vec3 delta(ioRandom.Coordinate(-0.5f, 0.5f) * mScenario.mExtent,
                                     ioRandom.Coordinate(-10.0f, 10.0f),
                                     ioRandom.Coordinate(-0.5f, 0.5f) * mScenario.mExtent);
                    body.mBounds = AABB(body.mBounds.mMin + delta, body.mBounds.mMax + delta);
                }
            }
            else if (inKind == OpKind::MoveSmall || ioRandom.Chance(0.5f))
                body.mBounds = SmallMove(ioRandom, body.mBounds);
            if (inKind == OpKind::ChangeLayer) body.mLayer = ioRandom.Layer();
            mStored[index] = body;
            moved.push_back(body);
        }
        // Moves of bodies that are not present (ignored by both)
        const uint32_t extra = inCount / 16 + (ioRandom.Chance(0.2f) ? 1 : 0);
        for (uint32_t i = 0; i < extra; ++i)
            if (BodyID id; StaleID(ioRandom, id)) moved.push_back({id, ioRandom.Bounds(), ioRandom.Layer()});
        std::shuffle(moved.begin(), moved.end(), ioRandom.mRandom);
        mOracle.NotifyBodiesAABBChanged(moved);
        mTested.NotifyBodiesAABBChanged(moved);
    }

    /// A small move: grid steps or a few centimetres to a metre, sometimes a resize, sometimes nothing.
    static AABB SmallMove(WorldRandom& ioRandom, const AABB& inBounds)
    {
        const float kind = ioRandom.Uniform(0.0f, 1.0f);
        if (kind < 0.05f) return inBounds;
        Vec3 delta;
        if (kind < 0.5f)
            delta = Vec3(0.5f * float(int(ioRandom.Index(3)) - 1), 0.5f * float(int(ioRandom.Index(3)) - 1),
                         0.5f * float(int(ioRandom.Index(3)) - 1));
        else
            delta = Vec3(ioRandom.Uniform(-0.4f, 0.4f), ioRandom.Uniform(-1.0f, 1.0f),
                         ioRandom.Uniform(-0.4f, 0.4f));
        AABB bounds(inBounds.mMin + delta, inBounds.mMax + delta);
        if (ioRandom.Chance(0.2f))
        {
            // Resize: the max corner moves by up to half a metre, never below the min corner
            const Vec3 grow(ioRandom.Coordinate(-0.5f, 0.5f), ioRandom.Coordinate(-0.5f, 0.5f),
                            ioRandom.Coordinate(-0.5f, 0.5f));
            bounds.mMax = (bounds.mMax + grow).cwiseMax(bounds.mMin);
        }
        return bounds;
    }

    /// A body corner or a face centre of a random present body (queries aimed exactly at faces), else a
    /// random position.
    Vec3 PointOnABody(WorldRandom& ioRandom) const
    {
        if (mPresent.Empty() || ioRandom.Chance(0.3f)) return ioRandom.Position();
        const AABB& bounds = mStored[mPresent.Pick(ioRandom)].mBounds;
        Vec3 point;
        for (int axis = 0; axis < 3; ++axis)
        {
            const uint32_t choice = ioRandom.Index(3);
            point[axis] = choice == 0 ? bounds.mMin[axis]
                                      : (choice == 1 ? bounds.mMax[axis]
                                                     : 0.5f * (bounds.mMin[axis] + bounds.mMax[axis]));
        }
        return point;
    }

    /// A query box: random, grown, a present body's bounds, a box touching one of its faces from outside, or
    /// (rarely) one that covers the whole world.
    AABB QueryBox(WorldRandom& ioRandom) const
    {
        const float kind = ioRandom.Uniform(0.0f, 1.0f);
        if (kind < 0.03f) return AABB(Vec3::Constant(-100.0f), Vec3::Constant(mScenario.mExtent + 100.0f));
        if (kind < 0.5f || mPresent.Empty())
        {
            const AABB box = ioRandom.Bounds();
            return ioRandom.Chance(0.3f) ? box.Expanded(ioRandom.Coordinate(0.0f, 20.0f)) : box;
        }
        AABB box = mStored[mPresent.Pick(ioRandom)].mBounds;
        if (kind < 0.65f) return box;
        // Touching from outside: the query box lies beyond one face and shares its plane
        const int axis = int(ioRandom.Index(3));
        const float depth = ioRandom.Coordinate(0.0f, 3.0f);
        if (ioRandom.Chance(0.5f))
        {
            box.mMin[axis] = box.mMax[axis];
            box.mMax[axis] += depth;
        }
        else
        {
            box.mMax[axis] = box.mMin[axis];
            box.mMin[axis] -= depth;
        }
        return box;
    }

    /// One query of each kind; empty when all agree.
    std::string CompareQueries(WorldRandom& ioRandom)
    {
        const ObjectLayerMask mask = ioRandom.Mask();

        const AABB box = QueryBox(ioRandom);
        const HitList boxHits = BoxHits(mOracle, box, mask);
        mTotalHits += boxHits.size();
        if (std::string difference = DescribeDifference(boxHits, BoxHits(mTested, box, mask));
            !difference.empty())
            return "CollideAABox " + ToString(box) + " " + MaskToString(mask) + ": " + difference;

        const Vec3 center = PointOnABody(ioRandom);
        const float radius = ioRandom.Chance(0.15f) ? 0.0f : ioRandom.Coordinate(0.0f, 15.0f);
        const HitList sphereHits = SphereHits(mOracle, center, radius, mask);
        mTotalHits += sphereHits.size();
        if (std::string difference =
                DescribeDifference(sphereHits, SphereHits(mTested, center, radius, mask));
            !difference.empty())
            return "CollideSphere " + ToString(center) + " radius " + std::to_string(radius) + " " +
                   MaskToString(mask) + ": " + difference;

        const Vec3 point = PointOnABody(ioRandom);
        const HitList pointHits = PointHits(mOracle, point, mask);
        mTotalHits += pointHits.size();
        if (std::string difference = DescribeDifference(pointHits, PointHits(mTested, point, mask));
            !difference.empty())
            return "CollidePoint " + ToString(point) + " " + MaskToString(mask) + ": " + difference;

        const Vec3 origin = PointOnABody(ioRandom);
        const RayCast ray{origin, ioRandom.Displacement(origin)};
        const auto castRay = [&](const BroadPhase& inBroadPhase, RayBodyVisitor inVisitor)
        { inBroadPhase.CastRay(ray, {mask}, inVisitor); };
        if (std::string difference = CompareCast(mOracle, mTested, castRay, mTotalHits); !difference.empty())
            return "CastRay from " + ToString(ray.mOrigin) + " along " + ToString(ray.mDirection) + " " +
                   MaskToString(mask) + ", " + difference;

        const Vec3 sweepCenter = PointOnABody(ioRandom);
        const Vec3 halfExtent(ioRandom.Coordinate(0.0f, 3.0f), ioRandom.Coordinate(0.0f, 3.0f),
                              ioRandom.Coordinate(0.0f, 3.0f));
        const AABB sweptBox =
            AABB::FromCenterExtent(sweepCenter, ioRandom.Chance(0.1f) ? Vec3::Zero() : halfExtent);
        const Vec3 displacement = ioRandom.Displacement(sweepCenter);
        const auto castBox = [&](const BroadPhase& inBroadPhase, RayBodyVisitor inVisitor)
        { inBroadPhase.CastAABox(sweptBox, displacement, {mask}, inVisitor); };
        if (std::string difference = CompareCast(mOracle, mTested, castBox, mTotalHits); !difference.empty())
            return "CastAABox " + ToString(sweptBox) + " along " + ToString(displacement) + " " +
                   MaskToString(mask) + ", " + difference;
        return {};
    }

    /// FindCollidingPairs over a random active list: present non-static bodies with a random probability, a
    /// few present static ones, and a few absent or stale ids (ignored by both), in random order. The
    /// collision table is the default one or, a quarter of the time, a random symmetric one (the same object
    /// to broad-phase layer mapping, which belongs to the broad phase).
    std::string ComparePairs(WorldRandom& ioRandom)
    {
        const float activeChance = ioRandom.Uniform(0.0f, 0.3f);
        std::vector<BodyID> active;
        for (uint32_t index : mPresent.Items())
        {
            if (active.size() >= mScenario.mMaxActive) break;
            const bool isStatic = mStored[index].mLayer == Layers::cStatic;
            if (ioRandom.Chance(isStatic ? 0.02f : activeChance)) active.push_back(mStored[index].mID);
        }
        const uint32_t extra = ioRandom.Index(4);
        for (uint32_t i = 0; i < extra; ++i)
            if (BodyID id; StaleID(ioRandom, id)) active.push_back(id);
        std::shuffle(active.begin(), active.end(), ioRandom.mRandom);

        LayerSetup layers = mLayers;
        const bool randomTable = ioRandom.Chance(0.25f);
        if (randomTable)
            for (ObjectLayer a = 0; a < 4; ++a)
                for (ObjectLayer b = a; b < 4; ++b)
                    layers.SetCollides(a, b, ioRandom.Chance(0.5f));

        const PairList pairs = CollidingPairs(mOracle, active, layers);
        mTotalPairs += pairs.size();
        if (std::string difference = DescribeDifference(pairs, CollidingPairs(mTested, active, layers));
            !difference.empty())
            return "FindCollidingPairs with " + std::to_string(active.size()) + " active ids" +
                   (randomTable ? " and a random collision table" : "") + ": " + difference;
        return {};
    }

    const Scenario mScenario;
    BroadPhaseBruteForce mOracle;
    Tested& mTested;
    const LayerSetup mLayers;
    std::vector<uint32_t> mSequence;     ///< Index -> sequence of its current (or last) id
    std::vector<BroadPhaseBody> mStored; ///< Index -> what the broad phases store while it is present
    IndexSet mPresent;                   ///< Added
    IndexSet mAbsent;                    ///< Neither added nor in a prepared batch
    std::vector<uint8_t> mPendingIndex;  ///< Index -> 1 while in a prepared batch
    std::vector<std::unique_ptr<PendingBatch>> mPending; ///< Prepared, not yet finalized or aborted
    size_t mTotalHits = 0;
    size_t mTotalPairs = 0;
};

// Generators

/// A seed for the details of an operation or a world. Not shrunk: a smaller seed is not a simpler case, and
/// shrinking it would replay a 10,000-body case dozens of times per operation.
rc::Gen<uint32_t> GenSeed()
{
    return rc::gen::noShrink(rc::gen::arbitrary<uint32_t>());
}

rc::Gen<Op> GenOp(uint32_t inMaxCount)
{
    return rc::gen::build<Op>(
        rc::gen::set(&Op::mKind, rc::gen::weightedElement<OpKind>({{8, OpKind::Update},
                                                                   {3, OpKind::RebuildAll},
                                                                   {9, OpKind::AddBatch},
                                                                   {3, OpKind::AbortBatch},
                                                                   {3, OpKind::PrepareDeferred},
                                                                   {3, OpKind::FinishDeferred},
                                                                   {7, OpKind::Remove},
                                                                   {9, OpKind::MoveSmall},
                                                                   {5, OpKind::MoveLarge},
                                                                   {5, OpKind::ChangeLayer}})),
        rc::gen::set(&Op::mCount, rc::gen::inRange<uint32_t>(0, inMaxCount + 1)),
        rc::gen::set(&Op::mSeed, GenSeed()));
}

/// Up to inMaxOps operations (the length grows with rapidcheck's size, so early cases are short).
rc::Gen<std::vector<Op>> GenOps(uint32_t inMaxCount, int inMaxOps)
{
    return rc::gen::scale(double(inMaxOps) / 100.0, rc::gen::container<std::vector<Op>>(GenOp(inMaxCount)));
}

/// Runs one case against a fresh quad tree.
void RunQuadTreeCase(const Scenario& inScenario, const std::vector<Op>& inOps)
{
    BroadPhaseQuadTree tested(cPoolSize, LayerSetup::CreateDefault());
    Harness<BroadPhaseQuadTree> harness(inScenario, tested);
    harness.Run(inOps);
}

/// Like RC_GTEST_PROP, with inMaxSuccess cases unless RC_PARAMS sets max_success (it also sets the seed).
template <class Testable> void CheckInGTest(Testable&& inTestable, int inMaxSuccess)
{
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    rc::detail::TestMetadata metadata;
    metadata.id = std::string(info->test_suite_name()) + "/" + info->name();
    metadata.description = info->name();
    rc::detail::TestParams params = rc::detail::configuration().testParams;
    if (params.maxSuccess == rc::detail::TestParams().maxSuccess) params.maxSuccess = inMaxSuccess;
    const rc::detail::TestResult result =
        rc::detail::checkTestable(std::forward<Testable>(inTestable), metadata, params);
    if (!result.template is<rc::detail::SuccessResult>())
    {
        std::ostringstream message;
        rc::detail::printResultMessage(result, message);
        FAIL() << message.str();
    }
}

// The properties

// Worlds of up to 2,500 bodies (ids from the 10,000 pool) of sizes from 15 m to 250 m, up to 40 operations.
RC_GTEST_PROP(QuadTreePropertyTest, MatchesBruteForceAfterAnyOperationSequence, ())
{
    const Scenario scenario = *rc::gen::build<Scenario>(
        rc::gen::set(&Scenario::mExtent, rc::gen::element(15.0f, 40.0f, 100.0f, 250.0f)),
        rc::gen::set(&Scenario::mInitialBodies, rc::gen::inRange<uint32_t>(0, 2501)),
        rc::gen::set(&Scenario::mInitialBatches, rc::gen::inRange<uint32_t>(1, 5)),
        rc::gen::set(&Scenario::mSeed, GenSeed()), rc::gen::set(&Scenario::mMaxActive, rc::gen::just(200u)),
        rc::gen::set(&Scenario::mQueries, rc::gen::just(5)));
    const std::vector<Op> ops = *GenOps(400, 40);
    RunQuadTreeCase(scenario, ops);
}

// The issue's world: every case starts with all 10,000 ids added (in 1 to 5 batches) in a 250 m world, then
// runs up to 16 operations of up to 1,500 bodies each (so adds only find ids after removes or aborts).
TEST(QuadTreePropertyTest, MatchesBruteForceWithTenThousandBodies)
{
    CheckInGTest(
        []
        {
            Scenario scenario;
            scenario.mExtent = 250.0f;
            scenario.mInitialBodies = cPoolSize;
            scenario.mInitialBatches = *rc::gen::inRange<uint32_t>(1, 6);
            scenario.mSeed = *GenSeed();
            scenario.mMaxActive = 400;
            scenario.mQueries = 6;
            const std::vector<Op> ops = *GenOps(1500, 16);
            BroadPhaseQuadTree tested(cPoolSize, LayerSetup::CreateDefault());
            Harness<BroadPhaseQuadTree> harness(scenario, tested);
            harness.Run(ops);
            // The comparison only means something if the queries and the pair search find things
            RC_ASSERT(harness.GetTotalHits() > 100u);
            RC_ASSERT(harness.GetTotalPairs() > 100u);
        },
        15);
}

// The comparison itself: a missing body, a wrong fraction and an extra pair are reported.
TEST(QuadTreePropertyTest, ComparisonReportsDifferences)
{
    const BodyID a(1, 1);
    const BodyID b(2, 1);
    EXPECT_TRUE(DescribeDifference(HitList{a, b}, HitList{a, b}).empty());
    const std::string missing = DescribeDifference(HitList{a, b}, HitList{a});
    EXPECT_NE(missing.find("only brute force (1): #2/1"), std::string::npos) << missing;
    EXPECT_FALSE(
        DescribeDifference(RayHitList{{a, 0.5f}}, RayHitList{{a, std::nextafter(0.5f, 1.0f)}}).empty());
    EXPECT_FALSE(DescribeDifference(PairList{{a, b}}, PairList{{a, b}, {b, a}}).empty());

    // And on real broad phases: the quad tree misses a body that only the oracle has
    BroadPhaseBruteForce oracle;
    BroadPhaseQuadTree tested(cPoolSize, LayerSetup::CreateDefault());
    const std::vector<BroadPhaseBody> both{{a, AABB(Vec3(0, 0, 0), Vec3(1, 1, 1)), Layers::cMoving}};
    const std::vector<BroadPhaseBody> oracleOnly{{b, AABB(Vec3(1, 0, 0), Vec3(2, 1, 1)), Layers::cMoving}};
    oracle.AddBodiesFinalize(oracle.AddBodiesPrepare(both));
    oracle.AddBodiesFinalize(oracle.AddBodiesPrepare(oracleOnly));
    tested.AddBodiesFinalize(tested.AddBodiesPrepare(both));
    const AABB query(Vec3(0.5f, 0.5f, 0.5f), Vec3(1.0f, 0.5f, 0.5f)); // Touches b's face
    EXPECT_FALSE(
        DescribeDifference(BoxHits(oracle, query, cAllObjectLayers), BoxHits(tested, query, cAllObjectLayers))
            .empty());
}

/// A bug to plant in the quad tree, to check that the property finds it.
enum class Fault : uint8_t
{
    PairsFromBothSides,   ///< Ignores the report-once rule for two active bodies
    RayFractionOneUlpOff, ///< CastRay reports each fraction one float step late
    RemoveSkipsLast,      ///< RemoveBodies forgets the last id of a call of several
    LayerChangeIgnored    ///< NotifyBodiesAABBChanged keeps the object layer of the add
};

/// BroadPhaseQuadTree with one planted fault.
class FaultyQuadTree final : public BroadPhase
{
public:
    explicit FaultyQuadTree(Fault inFault)
        : mInner(cPoolSize, LayerSetup::CreateDefault()), mFault(inFault), mLayerOfAdd(cPoolSize, 0)
    {
    }

    AddState AddBodiesPrepare(std::span<const BroadPhaseBody> inBodies) override
    {
        for (const BroadPhaseBody& body : inBodies)
            mLayerOfAdd[body.mID.GetIndex()] = body.mLayer;
        return mInner.AddBodiesPrepare(inBodies);
    }
    void AddBodiesFinalize(AddState inState) override { mInner.AddBodiesFinalize(inState); }
    void AddBodiesAbort(AddState inState) override { mInner.AddBodiesAbort(inState); }
    void RemoveBodies(std::span<const BodyID> inBodies) override
    {
        if (mFault == Fault::RemoveSkipsLast && inBodies.size() > 1)
            inBodies = inBodies.first(inBodies.size() - 1);
        mInner.RemoveBodies(inBodies);
    }
    void NotifyBodiesAABBChanged(std::span<const BroadPhaseBody> inBodies) override
    {
        if (mFault != Fault::LayerChangeIgnored) return mInner.NotifyBodiesAABBChanged(inBodies);
        std::vector<BroadPhaseBody> bodies(inBodies.begin(), inBodies.end());
        for (BroadPhaseBody& body : bodies)
            body.mLayer = mLayerOfAdd[body.mID.GetIndex()];
        mInner.NotifyBodiesAABBChanged(bodies);
    }
    bool ChangeBodyLayer(BodyID inBody, ObjectLayer inLayer, FunctionRef<void()> inWhileInBoth) override
    {
        return mInner.ChangeBodyLayer(inBody, inLayer, inWhileInBoth);
    }
    void Update() override { mInner.Update(); }
    void RebuildAll() { mInner.RebuildAll(); }
    bool Validate() const { return mInner.Validate(); }

    void CollideAABox(const AABB& inBox, const BroadPhaseQueryFilter& inFilter,
                      BodyVisitor inVisitor) const override
    {
        mInner.CollideAABox(inBox, inFilter, inVisitor);
    }
    void CollideSphere(const Vec3& inCenter, float inRadius, const BroadPhaseQueryFilter& inFilter,
                       BodyVisitor inVisitor) const override
    {
        mInner.CollideSphere(inCenter, inRadius, inFilter, inVisitor);
    }
    void CollidePoint(const Vec3& inPoint, const BroadPhaseQueryFilter& inFilter,
                      BodyVisitor inVisitor) const override
    {
        mInner.CollidePoint(inPoint, inFilter, inVisitor);
    }
    void CastRay(const RayCast& inRay, const BroadPhaseQueryFilter& inFilter,
                 RayBodyVisitor inVisitor) const override
    {
        if (mFault != Fault::RayFractionOneUlpOff) return mInner.CastRay(inRay, inFilter, inVisitor);
        mInner.CastRay(inRay, inFilter,
                       [&](BodyID inID, float inFraction)
                       { return inVisitor(inID, std::nextafter(inFraction, 2.0f)); });
    }
    void CastAABox(const AABB& inBox, const Vec3& inDisplacement, const BroadPhaseQueryFilter& inFilter,
                   RayBodyVisitor inVisitor) const override
    {
        mInner.CastAABox(inBox, inDisplacement, inFilter, inVisitor);
    }
    void FindCollidingPairs(std::span<const BodyID> inActiveBodies, const LayerSetup& inLayers,
                            BodyPairVisitor inVisitor, const ParallelRanges* = nullptr) const override
    {
        if (mFault != Fault::PairsFromBothSides)
            return mInner.FindCollidingPairs(inActiveBodies, inLayers, inVisitor);
        mInner.FindCollidingPairs(inActiveBodies, inLayers,
                                  [&](BodyID inActive, BodyID inOther)
                                  {
                                      inVisitor(inActive, inOther);
                                      if (std::find(inActiveBodies.begin(), inActiveBodies.end(), inOther) !=
                                          inActiveBodies.end())
                                          inVisitor(inOther, inActive);
                                  });
    }
    size_t GetBodyCount() const override { return mInner.GetBodyCount(); }

private:
    BroadPhaseQuadTree mInner;
    Fault mFault;
    std::vector<ObjectLayer> mLayerOfAdd; ///< Index -> object layer it was last added with
};

/// Swallows rapidcheck's reports: the failures below are expected, and must not be listed for reproduction.
class QuietListener final : public rc::detail::TestListener
{
public:
    void onTestCaseFinished(const rc::detail::CaseDescription&) override {}
    void onShrinkTried(const rc::detail::CaseDescription&, bool) override {}
    void onTestFinished(const rc::detail::TestMetadata&, const rc::detail::TestResult&) override {}
};

class QuadTreePropertyFaultTest : public ::testing::TestWithParam<Fault>
{
};

// The property must fail against each planted fault (without shrinking, to stay fast).
TEST_P(QuadTreePropertyFaultTest, PropertyDetectsPlantedFault)
{
    const Fault fault = GetParam();
    rc::detail::TestParams params;
    params.seed = 12345;
    params.maxSuccess = 100;
    params.disableShrinking = true;
    QuietListener listener;
    const rc::detail::TestResult result = rc::detail::checkTestable(
        [fault]
        {
            const Scenario scenario = *rc::gen::build<Scenario>(
                rc::gen::set(&Scenario::mExtent, rc::gen::element(15.0f, 40.0f)),
                rc::gen::set(&Scenario::mInitialBodies, rc::gen::inRange<uint32_t>(0, 500)),
                rc::gen::set(&Scenario::mSeed, GenSeed()));
            const std::vector<Op> ops = *GenOps(100, 20);
            FaultyQuadTree tested(fault);
            Harness<FaultyQuadTree> harness(scenario, tested);
            harness.Run(ops);
        },
        rc::detail::TestMetadata{}, params, listener);
    EXPECT_TRUE(result.template is<rc::detail::FailureResult>())
        << "the property missed fault " << int(fault);
}

INSTANTIATE_TEST_SUITE_P(Faults, QuadTreePropertyFaultTest,
                         ::testing::Values(Fault::PairsFromBothSides, Fault::RayFractionOneUlpOff,
                                           Fault::RemoveSkipsLast, Fault::LayerChangeIgnored));

} // namespace
} // namespace cairn
