#pragma once

// LinkMotion: where a crowd agent taking an off-mesh link is, from the Update it took the link on. It walks
// in a straight line from where it stood to the link's start (the link is its next corner, so the line is on
// the navmesh), then, for a link the crowd crosses itself, in a straight line along the link to its end, both
// at the agent's top speed. A link the game crosses holds the agent at its start until the game ends it.
//
// Threads: an agent's own, inside the crowd's Update or the calls between Updates (no shared state).

#include "cairn/navmesh/Crowd.h"

namespace cairn::navmesh
{

class LinkMotion
{
public:
    /// inLink's mStart and mEnd are on the navmesh at either end; inSpeed > 0 (m/s).
    LinkMotion(const Vec3& inFrom, const OffMeshLinkCrossing& inLink, float inSpeed, OffMeshLinkMode inMode);

    /// inDeltaTime seconds further; true once the agent has come off the link's end (never while the game
    /// crosses it).
    bool Advance(float inDeltaTime);
    Vec3 GetPosition() const;
    OffMeshLinkCrossing GetCrossing() const;

private:
    OffMeshLinkCrossing mLink;
    Vec3 mFrom;
    OffMeshLinkMode mMode;
    float mToStartSeconds; ///< The walk to the start
    float mAlongSeconds;   ///< The link itself
    float mElapsed = 0.0f;
};

} // namespace cairn::navmesh
