#pragma once

// IslandStage: from the narrow phase's links and constraints to the solver's plan. Build finalizes the
// islands that the narrow phase linked (AtomicUnionFind, O(N)) and groups the constraints by island; Order
// puts each island's constraints in solve order, sorts the islands by size, decides how each is solved and
// colors the large ones (IslandColoring.cpp). Serial, on the updating thread: the islands' numbering and
// the orders do not depend on the number of threads.

#include "islands/SolvePlan.h"
#include "solver/ContactConstraint.h"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace cairn::physics
{

struct StepContext;
struct ConstraintInfo;
class JointStage;

class IslandStage
{
public:
    /// Finalizes the islands (numbered by lowest body) and groups the constraints by island: O(N).
    void Build(const StepContext& inContext, std::span<const ConstraintInfo> inInfo);
    /// The solver's order: hashed within each island; large islands colored. An island with joints (inJoints)
    /// is colored, its joints with its contacts, when it holds a quarter of the step's contacts and joints
    /// (and at least cColoredIslandMinConstraints); a smaller one is solved whole by one thread
    /// (SolveIsland).
    void Order(const StepContext& inContext, std::span<ContactConstraint* const> inConstraints,
               std::span<const ConstraintInfo> inInfo, const JointStage& inJoints);

    SolvePlan& GetPlan() { return mPlan; }
    /// Bodies in the largest island (0 without islands). After Order.
    uint32_t GetLargestIslandSize(const StepContext& inContext) const;
    /// This step's colored islands, how many reused last step's coloring, whether the solve order was reused.
    uint32_t GetNumColoredIslands() const { return mNumColorings[mCurrentColorings]; }
    uint32_t GetNumColoringsReused() const { return mNumColoringsReused; }
    bool WasSolveOrderReused() const { return mSolveOrderReused; }

private:
    /// Islands with this many constraints or more are colored (with the wide solver; without it, only those
    /// that also hold cColoredIslandMinShare of the step), whatever the number of threads, so results do not
    /// depend on it. Those with a quarter of the step are solved by all threads together: one large island
    /// must not serialise the step
    static constexpr uint32_t cColoredIslandMinConstraints = 128;
    static constexpr uint32_t cColoredIslandMinShare = 4; ///< ... and at least 1/4 of the step's constraints
    /// The solve-order sort of an island uses RadixSort from this many items (std::sort below; the coloring,
    /// only for large islands, always uses RadixSort).
    static constexpr size_t cRadixSortMinItems = 256;
    /// Constraints that found no free color among 64: solved alone
    static constexpr uint32_t cSerialColor = 64;

    struct OrderItem
    {
        uint64_t mOrderKey;
        uint32_t mCacheIndex; ///< Tie-break (unique)
        uint32_t mConstraint; ///< Index into the step's constraints and their ConstraintInfo
        bool operator==(const OrderItem&) const = default;
    };
    struct ColorItem
    {
        uint64_t mKey;      ///< color << 32 | lowest dynamic active index (the visit order: both bodies)
        uint32_t mPosition; ///< In the island's hashed order
    };
    /// A coloring, kept for the next step: a resting pile's largest island has the same constraints between
    /// the same bodies in most steps, and its coloring (greedy, then a sort) is serial work
    struct ColoringRecord
    {
        /// Per constraint in solve order, then per joint in slot order: active index A << 32 | B
        std::vector<uint64_t> mBodyPairs;
        std::vector<uint32_t> mOrder;                    ///< Positions in mBodyPairs in color order
        std::array<uint32_t, cSerialColor + 1> mCount{}; ///< Constraints and joints per color
    };

    /// Orders a large island's constraints by color and lists its joints by color: within a color no two
    /// constraints or joints share a dynamic body.
    void ColorIsland(const StepContext& inContext, std::span<const ConstraintInfo> inInfo,
                     const JointStage& inJoints, uint32_t inIsland);
    /// The greedy coloring of ioRecord.mBodyPairs: fills its order and counts.
    void ComputeColoring(const StepContext& inContext, ColoringRecord& ioRecord);

    SolvePlan mPlan;
    std::vector<uint32_t> mIslandOrder;      ///< Scratch: islands, largest first
    std::vector<uint32_t> mIslandSizeStart;  ///< Scratch: the counting sort of mIslandOrder
    std::vector<uint32_t> mSmallIslands;     ///< Scratch for Order: the islands solved in groups
    std::vector<uint32_t> mConstraintIsland; ///< Scratch for Build: per constraint
    /// Per entry of mIslandConstraints once sorted (until ColorIsland reorders a colored island's entries);
    /// kept for the next step, whose sort input may be the same (Order)
    std::vector<OrderItem> mOrderItems;
    /// The sort's input: each island's items in constraint order (Build); and the input that mOrderItems
    /// holds sorted, with its islands' starts
    std::vector<OrderItem> mUnsortedOrderItems;
    std::vector<OrderItem> mSortedOrderItemsInput;
    std::vector<uint32_t> mSortedOrderItemsStarts;
    bool mSolveOrderReused = false;                ///< This step's (statistics)
    std::vector<OrderItem> mOrderScratch;          ///< Scratch: the radix sort's second buffer
    std::vector<uint64_t> mBodyColors;             ///< Scratch per active body: colors its constraints took
    std::vector<ColorItem> mColorItems;            ///< Scratch per constraint of the island being colored
    std::vector<ColorItem> mColorVisit;            ///< Scratch: the coloring's visit order (bodies, position)
    std::vector<ColorItem> mColorItemsScratch;     ///< Scratch: the radix sort's second buffer
    std::vector<ContactConstraint*> mColorScratch; ///< Scratch: the island's constraints reordered
    /// The records of this step [0, mNumColorings[mCurrentColorings]) and of the previous one (the other
    /// index); kept allocated
    std::array<std::vector<ColoringRecord>, 2> mColorings;
    std::array<uint32_t, 2> mNumColorings{};
    uint32_t mCurrentColorings = 0;
    uint32_t mNumColoringsReused = 0; ///< This step's (statistics; colored islands: its records)
};

} // namespace cairn::physics
