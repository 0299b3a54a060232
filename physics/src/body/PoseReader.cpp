#include "PublishedPoseStore.h"
#include "cairn/physics/body/BodyManager.h"

namespace cairn::physics
{

PoseReader::PoseReader(const BodyManager& inBodies)
    : mStore(inBodies.GetPublishedPoses()), mEpochReaders(mStore.GetReclaimer().Enter())
{
}

PoseReader::~PoseReader()
{
    EpochReclaimer::Exit(mEpochReaders);
}

bool PoseReader::Read(const BodyID& inID, PublishedPose& outPose) const
{
    if (inID.IsInvalid()) return false;
    return mStore.Read(inID.GetIndex(), outPose) && outPose.mID == inID;
}

} // namespace cairn::physics
