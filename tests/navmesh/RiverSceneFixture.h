#pragma once

// The river: ground crossed by a band of water with a dry bridge, the scene of the query tests (paths,
// straight walks, walls) and their area filters.

#include "NavMeshSceneFixture.h"

namespace cairn::navmesh::test
{

inline constexpr uint8_t cWater = 5;

class RiverSceneFixture : public NavMeshSceneFixture
{
protected:
    /// Ground from z = -10 to 10, crossed at z in [-1, 1] by a band of water, except for a dry bridge at
    /// x in [8, 10]. Start and end are on either side of the water at x = -8.
    void BuildRiver()
    {
        AddStaticBox(Vec3(0, -0.5f, -5.5f), Vec3(10, 0.5f, 4.5f));  // South bank
        AddStaticBox(Vec3(0, -0.5f, 5.5f), Vec3(10, 0.5f, 4.5f));   // North bank
        AddStaticBox(Vec3(-1, -0.5f, 0), Vec3(9, 0.5f, 1), cWater); // Water, x in [-10, 8]
        AddStaticBox(Vec3(9, -0.5f, 0), Vec3(1, 0.5f, 1));          // Bridge, x in [8, 10]
        MakeNavMesh();
        ASSERT_TRUE(RunUntilIdle());
    }

    static PathFilter NoSwimming()
    {
        PathFilter filter;
        filter.mExcludedAreas = uint64_t(1) << cWater;
        return filter;
    }

    const Vec3 mStart = Vec3(-8, 0, -6);
    const Vec3 mEnd = Vec3(-8, 0, 6);
};

} // namespace cairn::navmesh::test
