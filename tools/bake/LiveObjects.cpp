#include "LiveObjects.h"

#include <algorithm>

namespace cairn::bake
{
using namespace cairn::physics;

Result<std::vector<TileObject>> LiveObjects::Acquire(std::vector<SourceObject>& ioObjects)
{
    std::sort(ioObjects.begin(), ioObjects.end(),
              [](const SourceObject& inL, const SourceObject& inR) { return inL.mKey < inR.mKey; });
    BodyInterface& bodies = mPhysics.GetBodyInterface();
    std::vector<BodyID> made;
    auto undo = [&]
    {
        for (const BodyID& body : made)
            (void)bodies.DestroyBody(body); // Never added: nothing else to undo
    };
    for (const SourceObject& object : ioObjects)
    {
        if (mLive.contains(object.mKey)) continue;
        Result<SourceBody> source = mSource.MakeBody(object.mKey);
        if (!source)
        {
            undo();
            return source.GetError();
        }
        BodyCreationSettings settings;
        settings.mShape = source.Value().mShape;
        settings.mMotionType = MotionType::Static;
        settings.mObjectLayer = Layers::cStatic;
        settings.mNavMeshArea = source.Value().mArea;
        Result<BodyID> body = bodies.CreateBody(settings);
        if (!body)
        {
            undo();
            return MakeError(body.GetError().mCode, mSource.Describe(object.mKey) + ": " +
                                                        body.GetError().mMessage +
                                                        " (too many objects near the tiles in flight)");
        }
        made.push_back(body.Value());
    }
    // One broad-phase batch for the tile's new bodies: built aside, then linked in O(1)
    if (!made.empty())
    {
        Result<BodyInterface::AddBatch> batch = bodies.AddBodiesPrepare(made);
        if (!batch)
        {
            undo();
            return batch.GetError();
        }
        if (Status added = bodies.AddBodiesFinalize(batch.Value(), Activation::DontActivate); !added)
        {
            // The batch first: its bodies cannot be destroyed while it holds them
            (void)bodies.AddBodiesAbort(batch.Value());
            undo();
            return added.GetError();
        }
    }
    std::vector<TileObject> held;
    held.reserve(ioObjects.size());
    size_t next = 0;
    for (const SourceObject& object : ioObjects)
    {
        auto [it, inserted] = mLive.try_emplace(object.mKey);
        if (inserted)
        {
            it->second.mBody = made[next++];
            ++mNumMade;
        }
        ++it->second.mTiles;
        held.push_back({object.mKey, it->second.mBody});
    }
    mPeakLive = std::max(mPeakLive, uint32_t(mLive.size()));
    return held;
}

void LiveObjects::Release(const std::vector<TileObject>& inObjects)
{
    for (const TileObject& object : inObjects)
    {
        auto it = mLive.find(object.mKey);
        if (it == mLive.end() || --it->second.mTiles > 0) continue;
        Destroy(it->second.mBody);
        mLive.erase(it);
    }
}

void LiveObjects::Destroy(const BodyID& inBody)
{
    BodyInterface& bodies = mPhysics.GetBodyInterface();
    // Both only fail for a stale id, which a body of ours never is
    (void)bodies.RemoveBody(inBody);
    (void)bodies.DestroyBody(inBody);
}

} // namespace cairn::bake
