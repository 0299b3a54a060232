#include "LinkMotion.h"

#include <algorithm>

namespace cairn::navmesh
{

LinkMotion::LinkMotion(const Vec3& inFrom, const OffMeshLinkCrossing& inLink, float inSpeed,
                       OffMeshLinkMode inMode)
    : mLink(inLink), mFrom(inFrom), mMode(inMode), mToStartSeconds((inLink.mStart - inFrom).norm() / inSpeed),
      mAlongSeconds((inLink.mEnd - inLink.mStart).norm() / inSpeed)
{
}

bool LinkMotion::Advance(float inDeltaTime)
{
    mElapsed += inDeltaTime;
    return mMode == OffMeshLinkMode::Automatic && mElapsed >= mToStartSeconds + mAlongSeconds;
}

Vec3 LinkMotion::GetPosition() const
{
    if (mElapsed < mToStartSeconds) return mFrom + (mLink.mStart - mFrom) * (mElapsed / mToStartSeconds);
    if (mMode == OffMeshLinkMode::ByGame || mAlongSeconds <= 0.0f) return mLink.mStart;
    const float along = std::min(1.0f, (mElapsed - mToStartSeconds) / mAlongSeconds);
    return mLink.mStart + (mLink.mEnd - mLink.mStart) * along;
}

OffMeshLinkCrossing LinkMotion::GetCrossing() const
{
    OffMeshLinkCrossing crossing = mLink;
    crossing.mAtStart = mElapsed >= mToStartSeconds;
    return crossing;
}

} // namespace cairn::navmesh
