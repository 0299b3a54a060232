#pragma once

// PublishedPoseStore: the published pose of every body slot (see PublishedPose.h for what readers may see),
// and the shapes of destroyed bodies waiting until no reader can hold them.
//
// Threads and locks:
//  - A record: one writer at a time, the thread that holds the body's write lock or the physics step (which
//    holds every body lock); readers on any thread with no lock (a sequence lock per record, read again when
//    a write is in progress).
//  - Retired shapes: mRetiredMutex, taken by DestroyBody's thread and by whoever collects (the updating
//    thread after each Update). Never taken by a reader.
//  - The epoch: readers register in the reclaimer's stripes (never wait); it is advanced only under
//    mRetiredMutex, so by one thread at a time as EpochReclaimer requires.

#include "broadphase/EpochReclaimer.h"
#include "cairn/physics/body/Body.h"
#include "cairn/physics/body/PublishedPose.h"

#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

namespace cairn::physics
{

class PublishedPoseStore
{
public:
    explicit PublishedPoseStore(uint32_t inMaxBodies);
    ~PublishedPoseStore();
    PublishedPoseStore(const PublishedPoseStore&) = delete;
    PublishedPoseStore& operator=(const PublishedPoseStore&) = delete;

    /// Publishes inBody's current state. The caller holds the body's write lock or is the step.
    void Publish(const Body& inBody)
    {
        Record& record = BeginWrite(inBody);
        // Release, each: see BeginWrite
        record.mSequence.store(inBody.GetID().GetSequence(), std::memory_order_release);
        record.mFlags.store(PackFlags(inBody), std::memory_order_release);
        record.mShape.store(inBody.GetShape().get(), std::memory_order_release);
        StoreMotionAndEndWrite(record, inBody);
    }
    /// Publishes the position and rotation of a body whose other fields are published already (the step, at
    /// the end of a collision step: it changes nothing else of a body without publishing it whole). Returns
    /// the record's new version.
    uint32_t PublishMotion(const Body& inBody) { return StoreMotionAndEndWrite(BeginWrite(inBody), inBody); }
    /// The version of body slot inIndex's record, for its writer (the step) to tell whether anyone published
    /// it since.
    uint32_t GetVersion(uint32_t inIndex) const
    {
        // Relaxed: only a writer of the record calls it, and writers are serialised by the body's lock
        return mRecords[inIndex].mVersion.load(std::memory_order_relaxed);
    }

    /// What the physics step remembers of a body between its finishes (see
    /// FinishStage::Run): the displacement it last swept the body's bounds by for the broad
    /// phase, and the body's version right after it published it. While the version is still that one nobody
    /// has given the broad phase another box since (every change of a body's box publishes it). Kept in the
    /// record's spare bytes, on the line the step writes anyway; read and written by the step only (it holds
    /// every body lock), never by readers.
    struct StepMemory
    {
        Vec3 mSweep = Vec3::Zero();
        uint32_t mVersion = 1; ///< Odd, so never a published version until the step sets it
    };
    StepMemory& GetStepMemory(uint32_t inIndex) { return mRecords[inIndex].mStep; }

    /// Starts fetching a record that the caller will publish soon (the step, a range of bodies at a time).
    void Prefetch(uint32_t inIndex) const { __builtin_prefetch(&mRecords[inIndex], 1); }
    /// The record of body slot inIndex, whatever its id; false when it holds no body in the world. The
    /// caller is inside a read section of GetReclaimer().
    bool Read(uint32_t inIndex, PublishedPose& outPose) const;

    /// Keeps a destroyed body's shape until no reader can hold it (its record must name it no more). Any
    /// thread.
    void Retire(ShapeRef&& ioShape);
    /// Advances the epoch when no reader holds it back and frees the shapes no reader can reach. Any thread.
    void CollectRetired();

    const EpochReclaimer& GetReclaimer() const { return mReclaimer; }

private:
    /// One cache line a body, so that the step's threads, which publish bodies of scattered indices, never
    /// write the same line. Every field is atomic so that a reader racing a writer reads stale or torn data
    /// (and then discards it), never undefined behaviour.
    struct alignas(64) Record
    {
        std::atomic<uint32_t> mVersion{0};           ///< Odd while written
        std::atomic<uint32_t> mSequence{0};          ///< The body id's sequence (the index is the record's)
        std::atomic<uint32_t> mFlags{0};             ///< See PackFlags
        std::atomic<float> mPosition[3] = {0, 0, 0}; ///< The shape's origin, world
        std::atomic<float> mRotation[4] = {0, 0, 0, 1}; ///< x, y, z, w
        std::atomic<const Shape*> mShape{nullptr};
        StepMemory mStep; ///< Not published: the step's own (see StepMemory)
    };
    static_assert(sizeof(Record) == 64, "a published pose is one cache line");

    static uint32_t PackFlags(const Body& inBody);

    /// Makes the body's record odd (a write in progress) and returns it.
    Record& BeginWrite(const Body& inBody)
    {
        Record& record = mRecords[inBody.GetID().GetIndex()];
        // Relaxed load: only this thread writes the version now (the body's lock holder or the step)
        const uint32_t version = record.mVersion.load(std::memory_order_relaxed);
        // Relaxed: published by the release stores of the fields that follow (no fences: ThreadSanitizer does
        // not model them; a reader that acquires a new field value also sees this odd version)
        record.mVersion.store(version + 1, std::memory_order_relaxed);
        return record;
    }
    /// Stores the shape's origin and rotation, then makes the version even again; returns it.
    static uint32_t StoreMotionAndEndWrite(Record& ioRecord, const Body& inBody)
    {
        // The origin as Body::GetPosition finds it, so a reader sees the very transform the step had; most
        // shapes have their centre of mass at their origin, and then it is the centre of mass itself
        const Vec3 origin = inBody.mCenterOfMassOffset.isZero(0.0f) ? inBody.mPosition : inBody.GetPosition();
        // Release, each: see BeginWrite
        for (int i = 0; i < 3; ++i)
            ioRecord.mPosition[i].store(origin[i], std::memory_order_release);
        for (int i = 0; i < 4; ++i)
            ioRecord.mRotation[i].store(inBody.mRotation.coeffs()[i], std::memory_order_release);
        // Relaxed load: this thread made it odd. Release: a reader that acquires the even version sees every
        // field stored since
        const uint32_t version = ioRecord.mVersion.load(std::memory_order_relaxed) + 1;
        ioRecord.mVersion.store(version, std::memory_order_release);
        return version;
    }

    /// Frees the retired shapes no reader can reach. Caller holds mRetiredMutex.
    void FreeUnreachable();

    uint32_t mMaxBodies;
    std::unique_ptr<Record[]> mRecords;
    EpochReclaimer mReclaimer;
    std::mutex mRetiredMutex;
    struct RetiredShape
    {
        uint64_t mEpoch;
        ShapeRef mShape;
    };
    std::vector<RetiredShape> mRetired; ///< Guarded by mRetiredMutex; in epoch order
};

} // namespace cairn::physics
