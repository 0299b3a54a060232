#pragma once

// FinishStage: the end of a step for every active body: new bounds, the broad-phase move (bounds swept over
// the next step), the published pose (PublishedPose.h), in the order that keeps the broad phase holding a
// body's published bounds at every moment, and the sleep timer. Then IslandSleep decides which islands
// sleep.
//
// Threads: Run on the updating thread; its loop on the step's jobs, each range of bodies its own (the broad
// phase takes moves from any thread).

#include "cairn/physics/broadphase/BroadPhase.h"

#include <cstdint>
#include <vector>

namespace cairn::physics
{

struct StepContext;

class FinishStage
{
public:
    void Run(const StepContext& inContext);

private:
    /// When the finish publishes an active body's pose, against its broad-phase move
    enum class PublishOrder : uint8_t
    {
        BeforeMove,     ///< Its new bounds lie inside the box the broad phase holds for it
        AfterMove,      ///< Its new box covers its published bounds
        AfterGrownMove, ///< Its box is grown over its published bounds until then, and shrunk after
    };
    std::vector<BroadPhaseBody> mMovedBodies; ///< Scratch for the broad-phase notify, by active index
    std::vector<PublishOrder> mPublishOrders; ///< Scratch, by active index
};

} // namespace cairn::physics
