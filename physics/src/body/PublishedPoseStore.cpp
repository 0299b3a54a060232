#include "PublishedPoseStore.h"

#include "cairn/physics/LockWaits.h"
#include "math/CpuPause.h"

#include <thread>

namespace cairn::physics
{

namespace
{
constexpr uint32_t cInWorldBit = 1u << 0;
constexpr uint32_t cActiveBit = 1u << 1;
constexpr uint32_t cMotionShift = 2; // 2 bits
constexpr uint32_t cLayerShift = 8;  // 8 bits
constexpr uint32_t cAreaShift = 16;  // 8 bits
static_assert(sizeof(ObjectLayer) == 1 && sizeof(MotionType) == 1,
              "the flags word packs them in a byte each");

/// Retired shapes waiting before a collection is forced from DestroyBody (a world nobody updates)
constexpr size_t cCollectRetiredAt = 256;

} // namespace

PublishedPoseStore::PublishedPoseStore(uint32_t inMaxBodies)
    : mMaxBodies(inMaxBodies), mRecords(std::make_unique<Record[]>(inMaxBodies))
{
}

PublishedPoseStore::~PublishedPoseStore() = default;

uint32_t PublishedPoseStore::PackFlags(const Body& inBody)
{
    return (inBody.IsInWorld() ? cInWorldBit : 0u) | (inBody.IsActive() ? cActiveBit : 0u) |
           uint32_t(inBody.GetMotionType()) << cMotionShift |
           uint32_t(inBody.GetObjectLayer()) << cLayerShift | uint32_t(inBody.GetNavMeshArea()) << cAreaShift;
}

bool PublishedPoseStore::Read(uint32_t inIndex, PublishedPose& outPose) const
{
    if (inIndex >= mMaxBodies) return false;
    const Record& record = mRecords[inIndex];
    for (uint32_t attempt = 1;; ++attempt)
    {
        // Acquire: pairs with the release store of the even version
        const uint32_t before = record.mVersion.load(std::memory_order_acquire);
        if ((before & 1) == 0)
        {
            // Acquire, each: keeps the version re-read below after these loads, and a field value from a
            // write in progress implies its odd version is visible to that re-read
            const uint32_t sequence = record.mSequence.load(std::memory_order_acquire);
            const uint32_t flags = record.mFlags.load(std::memory_order_acquire);
            for (int i = 0; i < 3; ++i)
                outPose.mTransform.mPosition[i] = record.mPosition[i].load(std::memory_order_acquire);
            for (int i = 0; i < 4; ++i)
                outPose.mTransform.mRotation.coeffs()[i] =
                    record.mRotation[i].load(std::memory_order_acquire);
            outPose.mShape = record.mShape.load(std::memory_order_acquire);
            // Relaxed: ordered after the acquire loads above
            if (record.mVersion.load(std::memory_order_relaxed) == before)
            {
                outPose.mID = BodyID(inIndex, sequence);
                outPose.mActive = (flags & cActiveBit) != 0;
                outPose.mMotionType = MotionType((flags >> cMotionShift) & 3u);
                outPose.mLayer = ObjectLayer(flags >> cLayerShift);
                outPose.mNavMeshArea = uint8_t(flags >> cAreaShift);
                outPose.mVersion = before;
                return (flags & cInWorldBit) != 0 && outPose.mShape != nullptr;
            }
        }
        // A write is in progress: it is a few dozen nanoseconds of stores, unless its thread lost its core
        if (attempt % 64 == 0)
            std::this_thread::yield();
        else
            CpuPause();
    }
}

void PublishedPoseStore::Retire(ShapeRef&& ioShape)
{
    if (ioShape == nullptr) return;
    const auto lock = LockedCountingWait(mRetiredMutex, LockKind::Body);
    // The epoch read after the record stopped naming the shape: a reader that still holds it entered at or
    // before this epoch
    mRetired.push_back({mReclaimer.GetEpoch(), std::move(ioShape)});
    if (mRetired.size() >= cCollectRetiredAt)
    {
        mReclaimer.TryAdvance();
        FreeUnreachable();
    }
}

void PublishedPoseStore::CollectRetired()
{
    const auto lock = LockedCountingWait(mRetiredMutex, LockKind::Body);
    if (mRetired.empty()) return;
    mReclaimer.TryAdvance();
    FreeUnreachable();
}

void PublishedPoseStore::FreeUnreachable()
{
    size_t freed = 0;
    while (freed < mRetired.size() && mReclaimer.IsSafeToFree(mRetired[freed].mEpoch))
        ++freed;
    mRetired.erase(mRetired.begin(), mRetired.begin() + std::ptrdiff_t(freed));
}

} // namespace cairn::physics
