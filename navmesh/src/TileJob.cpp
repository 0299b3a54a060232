#include "TileJob.h"

namespace cairn::navmesh
{
using namespace cairn::physics;

jobs::BackgroundStep TileJob::Finish(std::optional<Result<BuiltTile>> inResult, jobs::BackgroundStep inStep)
{
    mResult = std::move(inResult);
    mFinished.store(true, std::memory_order_release); // Publishes mResult and the stats to the scheduler
    return inStep;
}

jobs::BackgroundStep TileJob::Step(jobs::BackgroundTaskContext& ioContext)
{
    if (ioContext.IsCancelRequested()) return Finish(std::nullopt, jobs::BackgroundStep::Done);
    switch (mStage)
    {
    case Stage::Collect:
        mCollector.FindBodies(mBox, mInclusion, mBodies);
        mCollector.CollectTriangles(mBox, mInclusion, mBodies, mGeometry, mStats);
        mStage = Stage::Build;
        ioContext.SetProgress(0.4f);
        return jobs::BackgroundStep::Continue;

    case Stage::Build:
    {
        Result<BuiltTile> built = BuildTile(mProfile, mGrid, mTile, mGeometry, mLinks);
        if (!built) ioContext.SetError(built.GetError().mMessage);
        const jobs::BackgroundStep step = built ? jobs::BackgroundStep::Done : jobs::BackgroundStep::Failed;
        return Finish(std::move(built), step);
    }
    }
    return Finish(std::nullopt, jobs::BackgroundStep::Done);
}

} // namespace cairn::navmesh
