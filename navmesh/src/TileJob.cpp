#include "TileJob.h"

#include <thread>

namespace cairn::navmesh
{

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
    case Stage::Static:
        mCollector.FindBodies(mBox, mInclusion, mBodies);
        mCollector.CollectTriangles(mBox, mInclusion, mBodies, mGeometry, mBusy, mStats, BodyKinds::Static);
        mStaticTriangles = mGeometry.GetNumTriangles();
        mStage = Stage::Others;
        ioContext.SetProgress(0.3f);
        return jobs::BackgroundStep::Continue;

    case Stage::Others:
        mBusy.clear();
        mCollector.CollectTriangles(mBox, mInclusion, mBodies, mGeometry, mBusy, mStats,
                                    BodyKinds::NonStatic);
        if (!mBusy.empty())
        {
            // The step holds a body: drop this pass's triangles (so they keep their order) and try again in
            // the next chunk, after a pause short next to a step
            mGeometry.mVertices.resize(size_t(mStaticTriangles) * 9);
            mGeometry.mTriangles.resize(size_t(mStaticTriangles) * 3);
            mGeometry.mAreas.resize(size_t(mStaticTriangles));
            ++mBusyRetries;
            std::this_thread::sleep_for(std::chrono::microseconds(200));
            return jobs::BackgroundStep::Continue;
        }
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
