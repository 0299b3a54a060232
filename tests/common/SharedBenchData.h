#pragma once

// Loaders for the shared benchmark workload (../shared/bench, described by its SPEC.md) into plain structs,
// for tests and benchmarks. Every loader returns an error with a message when the file is missing or
// malformed, so a caller can skip (the project must run without ../shared). Plain functions, no shared state:
// any thread.

#include "cairn/physics/math/AABB.h"
#include "cairn/physics/math/Result.h"

#include <string>
#include <vector>

namespace cairn
{
using namespace cairn::physics;

/// A box of world20k_static.csv or world20k_dynamic.csv: rotated by mYaw about +Y.
struct BenchBox
{
    int mTile = -1;                  ///< World tile 0..27 (static world only; -1 for dynamic boxes)
    Vec3 mCenter = Vec3::Zero();     ///< Metres
    Vec3 mHalfExtent = Vec3::Zero(); ///< Metres, in the box's own axes
    float mYaw = 0.0f;               ///< Radians about +Y

    /// Exact world AABB of the rotated box, in float32 (ex = |cos| hx + |sin| hz, ey = hy, ez = |sin| hx +
    /// |cos| hz).
    AABB GetWorldBounds() const;
};

/// A segment of rays10k_50m.csv: points mOrigin + t * mDisplacement, t in [0, 1].
struct BenchRay
{
    Vec3 mOrigin = Vec3::Zero();       ///< Metres
    Vec3 mDisplacement = Vec3::Zero(); ///< Metres (length 50)
};

/// The whole workload.
struct SharedBenchData
{
    std::vector<BenchBox> mStatic;   ///< world20k_static.csv: 20,020 boxes
    std::vector<BenchBox> mDynamic;  ///< world20k_dynamic.csv: 2,000 boxes
    std::vector<AABB> mQueryBoxes;   ///< queries10k_box12_8.csv: 10,000 boxes
    std::vector<BenchRay> mRays;     ///< rays10k_50m.csv: 10,000 rays
    std::vector<uint32_t> mRemovals; ///< remove1k.csv: 1,000 row indices into mStatic
};

/// The directory holding the workload: $CAIRN_SHARED_DIR/bench if that variable is set, else the
/// CAIRN_SHARED_DIR compile definition + /bench, else /work/shared/bench.
std::string GetSharedBenchDir();
/// ../shared/data (CAIRN_SHARED_DIR overrides ../shared): the Recast demo meshes and other level data.
std::string GetSharedDataDir();

/// world20k_static.csv (with tile column) or world20k_dynamic.csv (without), chosen by inWithTile.
Result<std::vector<BenchBox>> LoadBenchBoxes(const std::string& inPath, bool inWithTile);
/// queries10k_box12_8.csv.
Result<std::vector<AABB>> LoadBenchQueryBoxes(const std::string& inPath);
/// rays10k_50m.csv.
Result<std::vector<BenchRay>> LoadBenchRays(const std::string& inPath);
/// remove1k.csv.
Result<std::vector<uint32_t>> LoadBenchRemovals(const std::string& inPath);
/// All five files of inDir (GetSharedBenchDir() by default); checks removal indices against the static world.
Result<SharedBenchData> LoadSharedBenchData(const std::string& inDir = GetSharedBenchDir());

} // namespace cairn
