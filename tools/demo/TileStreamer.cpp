#include "TileStreamer.h"

#include "common/FrameTimes.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#if defined(__linux__)
#include <sched.h>
#endif

namespace cairn::demo
{
using namespace cairn::physics;

namespace
{
using Clock = std::chrono::steady_clock;

} // namespace

TileStreamer::TileStreamer(PhysicsSystem& ioPhysics, const WorldGenerator& inGenerator,
                           float inCollisionRadius)
    : mPhysics(ioPhysics), mGenerator(inGenerator), mCollisionRadius(inCollisionRadius),
      mBodiesBefore(ioPhysics.GetBodyManager().GetNumBodies())
{
    mThread = std::thread([this] { ThreadMain(); });
}

TileStreamer::~TileStreamer()
{
    {
        std::lock_guard lock(mMutex);
        mStop = true;
    }
    mWake.notify_all();
    if (mThread.joinable()) mThread.join();
}

void TileStreamer::SetFocus(const Vec3& inPlayer, const Vec3& inAhead)
{
    {
        // The main thread never waits for the loading thread: if it holds the mutex, the focus is handed
        // over at the next frame (the player moves a few centimetres a frame)
        std::unique_lock lock(mMutex, std::try_to_lock);
        if (!lock.owns_lock()) return;
        const WorldTile before = mGenerator.TileAt(mPlayer.x(), mPlayer.z());
        const WorldTile beforeAhead = mGenerator.TileAt(mAhead.x(), mAhead.z());
        mPlayer = inPlayer;
        mAhead = inAhead;
        // Only a new tile under the player or ahead changes what is wanted
        if (mHasFocus && before == mGenerator.TileAt(inPlayer.x(), inPlayer.z()) &&
            beforeAhead == mGenerator.TileAt(inAhead.x(), inAhead.z()))
            return;
        mHasFocus = true;
        mSettled = false;
    }
    mWake.notify_one();
}

bool TileStreamer::IsSettled() const
{
    std::lock_guard lock(mMutex);
    return mHasFocus && mSettled;
}

TileStreamer::Stats TileStreamer::GetStats() const
{
    std::lock_guard lock(mMutex);
    return mStats;
}

std::vector<WorldTile> TileStreamer::GetLoadedTiles() const
{
    std::lock_guard lock(mMutex);
    std::vector<WorldTile> tiles;
    for (const auto& [tile, high] : mLoadedLod)
        tiles.push_back(tile);
    return tiles;
}

bool TileStreamer::TakeDoorsIfChanged(uint64_t& ioVersion, std::vector<StreamedDoor>& outDoors) const
{
    std::unique_lock lock(mMutex, std::try_to_lock);
    if (!lock.owns_lock() || ioVersion == mDoorsVersion) return false;
    ioVersion = mDoorsVersion;
    outDoors = mDoors;
    return true;
}

void TileStreamer::PublishDoorsLocked()
{
    mDoors.clear();
    for (const auto& [tile, loaded] : mTiles)
        mDoors.insert(mDoors.end(), loaded.mDoors.begin(), loaded.mDoors.end());
    ++mDoorsVersion;
}

bool TileStreamer::IsTerrain(const BodyID& inBody) const
{
    std::lock_guard lock(mTerrainMutex);
    return mTerrain.contains(inBody);
}

void TileStreamer::NoteError(std::string inError)
{
    std::lock_guard lock(mMutex);
    if (mStats.mErrors.size() < 20) mStats.mErrors.push_back(std::move(inError));
}

std::map<WorldTile, bool> TileStreamer::WantedTiles(const Vec3& inPlayer, const Vec3& inAhead) const
{
    std::map<WorldTile, bool> wanted;
    const int reach = int(std::ceil(mCollisionRadius));
    for (const Vec3* focus : {&inPlayer, &inAhead})
    {
        const WorldTile centre = mGenerator.TileAt(focus->x(), focus->z());
        for (int dz = -reach; dz <= reach; ++dz)
            for (int dx = -reach; dx <= reach; ++dx)
            {
                if (float(dx * dx + dz * dz) > mCollisionRadius * mCollisionRadius) continue;
                const WorldTile tile{centre.mX + dx, centre.mZ + dz};
                // High LOD: the 3 x 3 tiles around the player itself
                const bool high = focus == &inPlayer && std::abs(dx) <= 1 && std::abs(dz) <= 1;
                auto [it, inserted] = wanted.try_emplace(tile, high);
                if (!inserted) it->second = it->second || high;
            }
    }
    return wanted;
}

bool TileStreamer::AddBatch(const std::vector<BodyCreationSettings>& inSettings, Activation inActivation,
                            std::vector<BodyID>& outIDs)
{
    BodyInterface& bodies = mPhysics.GetBodyInterface();
    const size_t first = outIDs.size();
    for (const BodyCreationSettings& settings : inSettings)
    {
        Result<BodyID> id = bodies.CreateBody(settings);
        if (!id)
        {
            NoteError("create body: " + id.GetError().mMessage);
            continue;
        }
        outIDs.push_back(id.Value());
    }
    const std::span<const BodyID> created(outIDs.data() + first, outIDs.size() - first);
    // A batch that fails takes its bodies with it: none is left created but not in the world
    auto dropCreated = [&]
    {
        for (const BodyID& id : created)
            (void)bodies.DestroyBody(id);
        outIDs.resize(first);
        return false;
    };
    Result<BodyInterface::AddBatch> batch = bodies.AddBodiesPrepare(created);
    if (!batch)
    {
        NoteError("prepare batch: " + batch.GetError().mMessage);
        return dropCreated();
    }
    const Clock::time_point link = Clock::now();
    if (Status finalized = bodies.AddBodiesFinalize(batch.Value(), inActivation); !finalized)
    {
        NoteError("finalize batch: " + finalized.GetError().mMessage);
        (void)bodies.AddBodiesAbort(batch.Value()); // Its bodies cannot be destroyed while it holds them
        return dropCreated();
    }
    const double linkMs = tools::MillisecondsSince(link);
    std::lock_guard lock(mMutex);
    mStats.mStreamLinkMs.push_back(linkMs);
    return true;
}

void TileStreamer::LoadTile(const WorldTile& inTile, LoadedTile& outTile)
{
    TileContent content = mGenerator.GenerateTile(inTile, false);
    std::vector<BodyCreationSettings> statics;
    statics.reserve(content.mProps.size() + 1);
    statics.push_back(std::move(content.mTerrain));
    for (BodyCreationSettings& prop : content.mProps)
        statics.push_back(std::move(prop));
    AddBatch(statics, Activation::DontActivate, outTile.mStatic);
    if (!outTile.mStatic.empty())
    {
        std::lock_guard lock(mTerrainMutex);
        mTerrain.insert(outTile.mStatic.front());
    }
    AddDoors(content.mDoors, outTile);
}

void TileStreamer::AddDoors(std::vector<DoorSpec>& ioDoors, LoadedTile& ioTile)
{
    if (ioDoors.empty()) return;
    std::vector<BodyCreationSettings> panels;
    for (const DoorSpec& door : ioDoors)
        panels.push_back(door.mPanel);
    std::vector<BodyID> created;
    if (!AddBatch(panels, Activation::DontActivate, created)) return;
    if (created.size() != ioDoors.size()) // A panel refused: which is which is lost, so none gets a hinge
    {
        RemoveBodies(created);
        return;
    }
    ConstraintInterface& joints = mPhysics.GetConstraintInterface();
    for (size_t i = 0; i < ioDoors.size(); ++i)
    {
        HingeConstraintSettings hinge = ioDoors[i].mHinge;
        hinge.mBodyB = created[i];
        Result<ConstraintID> joint = joints.AddHinge(hinge);
        if (!joint)
        {
            NoteError("door hinge: " + joint.GetError().mMessage);
            std::vector<BodyID> panel{created[i]};
            RemoveBodies(panel);
            continue;
        }
        ioTile.mDoors.push_back({created[i], joint.Value(), ioDoors[i].mOutside, ioDoors[i].mInside,
                                 ioDoors[i].mPeriod, ioDoors[i].mPhase});
    }
}

void TileStreamer::RemoveDoors(LoadedTile& ioTile)
{
    ConstraintInterface& joints = mPhysics.GetConstraintInterface();
    std::vector<BodyID> panels;
    for (const StreamedDoor& door : ioTile.mDoors)
    {
        if (Status removed = joints.Remove(door.mHinge); !removed)
            NoteError("remove door hinge: " + removed.GetError().mMessage);
        panels.push_back(door.mPanel);
    }
    ioTile.mDoors.clear();
    RemoveBodies(panels);
}

void TileStreamer::AddDynamic(const WorldTile& inTile, LoadedTile& ioTile)
{
    // Created asleep, resting where they were placed, as a game streams in its props: they cost the step
    // nothing until something touches them
    TileContent content = mGenerator.GenerateTile(inTile, true);
    AddBatch(content.mDynamic, Activation::DontActivate, ioTile.mDynamic);
}

void TileStreamer::RemoveBodies(std::vector<BodyID>& ioBodies)
{
    BodyInterface& bodies = mPhysics.GetBodyInterface();
    for (const BodyID& id : ioBodies)
    {
        if (Status removed = bodies.RemoveBody(id); !removed)
            NoteError("remove body: " + removed.GetError().mMessage);
        if (Status destroyed = bodies.DestroyBody(id); !destroyed)
            NoteError("destroy body: " + destroyed.GetError().mMessage);
    }
    std::lock_guard lock(mTerrainMutex);
    for (const BodyID& id : ioBodies)
        mTerrain.erase(id);
    ioBodies.clear();
}

void TileStreamer::ThreadMain()
{
#if defined(__linux__)
    // Streaming is background work: it runs when the frame's threads leave a core idle (SCHED_IDLE), so it
    // never preempts a job thread in the middle of a parallel phase (with nice alone it did, for 1-3 ms)
    sched_param idle{};
    (void)sched_setscheduler(0, SCHED_IDLE, &idle); // 0: this thread
#endif
    for (;;)
    {
        Vec3 player, ahead;
        {
            std::unique_lock lock(mMutex);
            mWake.wait(lock, [&] { return mStop || (mHasFocus && !mSettled); });
            if (mStop) return;
            player = mPlayer;
            ahead = mAhead;
        }
        const std::map<WorldTile, bool> wanted = WantedTiles(player, ahead);

        // One change at a time, nearest first, so that a new focus is seen between tiles: out before in (the
        // memory budget), then tiles that need to change LOD, then new tiles
        bool changed = false;
        for (auto it = mTiles.begin(); it != mTiles.end() && !changed; ++it)
            if (!wanted.contains(it->first))
            {
                const Clock::time_point start = Clock::now();
                RemoveBodies(it->second.mDynamic);
                RemoveDoors(it->second);
                RemoveBodies(it->second.mStatic);
                const double ms = tools::MillisecondsSince(start);
                mTiles.erase(it);
                std::lock_guard lock(mMutex);
                mStats.mStreamOutMs.push_back(ms);
                ++mStats.mTilesOut;
                changed = true;
                break;
            }
        if (!changed)
        {
            // The wanted tile nearest the player that is missing or at the wrong LOD
            const WorldTile centre = mGenerator.TileAt(player.x(), player.z());
            const WorldTile* best = nullptr;
            int bestDistance = 1 << 30;
            for (const auto& [tile, high] : wanted)
            {
                auto loaded = mTiles.find(tile);
                const bool needsWork = loaded == mTiles.end() || high != !loaded->second.mDynamic.empty();
                const int distance = (tile.mX - centre.mX) * (tile.mX - centre.mX) +
                                     (tile.mZ - centre.mZ) * (tile.mZ - centre.mZ);
                if (needsWork && distance < bestDistance)
                {
                    best = &tile;
                    bestDistance = distance;
                }
            }
            if (best != nullptr)
            {
                const WorldTile tile = *best;
                const bool high = wanted.at(tile);
                auto [it, inserted] = mTiles.try_emplace(tile);
                const Clock::time_point start = Clock::now();
                if (inserted) LoadTile(tile, it->second);
                if (high && it->second.mDynamic.empty())
                    AddDynamic(tile, it->second);
                else if (!high)
                    RemoveBodies(it->second.mDynamic);
                const double ms = tools::MillisecondsSince(start);
                std::lock_guard lock(mMutex);
                if (inserted)
                {
                    mStats.mStreamInMs.push_back(ms);
                    ++mStats.mTilesIn;
                }
                changed = true;
            }
        }

        std::lock_guard lock(mMutex);
        uint32_t statics = 0, dynamics = 0;
        mLoadedLod.clear();
        for (const auto& [tile, loaded] : mTiles)
        {
            statics += uint32_t(loaded.mStatic.size());
            dynamics += uint32_t(loaded.mDynamic.size() + loaded.mDoors.size());
            mLoadedLod[tile] = !loaded.mDynamic.empty();
        }
        mStats.mStaticBodies = statics;
        mStats.mDynamicBodies = dynamics;
        mStats.mStaticPeak = std::max(mStats.mStaticPeak, statics);
        mStats.mDynamicPeak = std::max(mStats.mDynamicPeak, dynamics);
        if (changed) PublishDoorsLocked(); // A pass changes one tile at most: its doors may have come or gone
        // Settled when a pass found nothing to do for the focus it read (a newer focus clears it again)
        if (!changed && player == mPlayer && ahead == mAhead) mSettled = true;
    }
}

uint32_t TileStreamer::CountLostOrDuplicated() const
{
    std::lock_guard lock(mMutex);
    const int64_t expected = int64_t(mBodiesBefore) + mStats.mStaticBodies + mStats.mDynamicBodies;
    return uint32_t(std::abs(int64_t(mPhysics.GetBodyManager().GetNumBodies()) - expected));
}

uint32_t TileStreamer::UnloadAllAndCheck()
{
    {
        std::lock_guard lock(mMutex);
        mStop = true;
    }
    mWake.notify_all();
    if (mThread.joinable()) mThread.join();
    // Every body this streamer made must still be there, in the world, exactly once
    BodyInterface& bodies = mPhysics.GetBodyInterface();
    uint32_t problems = 0;
    std::set<BodyID> seen;
    auto check = [&](const BodyID& inID)
    {
        Result<bool> added = bodies.IsAdded(inID);
        if (!added || !added.Value() || !seen.insert(inID).second) ++problems;
    };
    for (auto& [tile, loaded] : mTiles)
    {
        for (const std::vector<BodyID>* list : {&loaded.mStatic, &loaded.mDynamic})
            for (const BodyID& id : *list)
                check(id);
        for (const StreamedDoor& door : loaded.mDoors)
            check(door.mPanel);
    }
    if (mPhysics.GetBodyManager().GetNumBodies() != mBodiesBefore + seen.size()) ++problems;
    for (auto& [tile, loaded] : mTiles)
    {
        RemoveBodies(loaded.mDynamic);
        RemoveDoors(loaded);
        RemoveBodies(loaded.mStatic);
    }
    mTiles.clear();
    if (mPhysics.GetBodyManager().GetNumBodies() != mBodiesBefore) ++problems;
    return problems;
}

} // namespace cairn::demo
