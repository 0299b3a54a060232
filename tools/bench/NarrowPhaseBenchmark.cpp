// cairn-bench-narrowphase: the hot pair routines of the narrow phase, with Google Benchmark. Each benchmark
// prints ns per call and, as counters, the share of pairs that made contact and the manifolds per call: the
// proof that the work was done.

#include "cairn/physics/narrowphase/CollideShapes.h"
#include "cairn/physics/shapes/BoxShape.h"
#include "cairn/physics/shapes/HeightFieldShape.h"
#include "cairn/physics/shapes/SphereShape.h"
#include "cairn/physics/shapes/TriangleMeshShape.h"
#include "narrowphase/CollideBoxBox.h"
#include "narrowphase/CollideSphereBox.h"
#include "narrowphase/CollideSphereSphere.h"

#include <array>
#include <benchmark/benchmark.h>
#include <cmath>
#include <random>
#include <vector>

using namespace cairn;
using namespace cairn::physics;

namespace
{
struct Pair
{
    Transform mA;
    Transform mB;
};

/// Random nearby poses: most unit shapes overlap, as in a pile.
const std::vector<Pair>& RandomPairs()
{
    static const std::vector<Pair> pairs = []
    {
        std::mt19937 random(3);
        std::uniform_real_distribution<float> offset(-0.9f, 0.9f);
        std::normal_distribution<float> gauss;
        std::vector<Pair> result;
        for (int i = 0; i < 10000; ++i)
            result.push_back(
                {{Vec3(offset(random), offset(random), offset(random)),
                  Quat(gauss(random), gauss(random), gauss(random), gauss(random)).normalized()},
                 {Vec3(offset(random), offset(random), offset(random)),
                  Quat(gauss(random), gauss(random), gauss(random), gauss(random)).normalized()}});
        return result;
    }();
    return pairs;
}

/// Runs inCollide over the random pairs, one pair per iteration.
template <class F> void RunPairs(benchmark::State& ioState, F inCollide)
{
    const std::vector<Pair>& pairs = RandomPairs();
    size_t next = 0;
    int64_t contacts = 0;
    for (auto _ : ioState)
    {
        const Pair& pair = pairs[next];
        next = next + 1 == pairs.size() ? 0 : next + 1;
        const bool hit = inCollide(pair);
        contacts += hit ? 1 : 0;
        benchmark::DoNotOptimize(hit);
    }
    ioState.counters["contact_share"] = double(contacts) / double(ioState.iterations());
}

void BM_BoxBox(benchmark::State& ioState)
{
    const auto box = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    ContactManifold manifold;
    RunPairs(ioState,
             [&](const Pair& inP) { return CollideBoxBox(*box, inP.mA, *box, inP.mB, {}, manifold); });
}

void BM_SphereBox(benchmark::State& ioState)
{
    const auto box = BoxShape::Create(Vec3(0.5f, 0.5f, 0.5f)).Value();
    const auto sphere = SphereShape::Create(0.5f).Value();
    ContactManifold manifold;
    RunPairs(ioState,
             [&](const Pair& inP) { return CollideSphereBox(*sphere, inP.mA, *box, inP.mB, {}, manifold); });
}

void BM_SphereSphere(benchmark::State& ioState)
{
    const auto sphere = SphereShape::Create(0.5f).Value();
    ContactManifold manifold;
    RunPairs(ioState, [&](const Pair& inP)
             { return CollideSphereSphere(*sphere, inP.mA, *sphere, inP.mB, {}, manifold); });
}

/// A box resting on a flat 4 x 4 grid mesh (32 triangles), touching 2 to 8 of them.
void BM_BoxOnMesh(benchmark::State& ioState)
{
    std::vector<Vec3> vertices;
    std::vector<std::array<uint32_t, 3>> triangles;
    for (uint32_t z = 0; z <= 4; ++z)
        for (uint32_t x = 0; x <= 4; ++x)
            vertices.emplace_back(float(x), 0.0f, float(z));
    for (uint32_t z = 0; z < 4; ++z)
        for (uint32_t x = 0; x < 4; ++x)
        {
            const uint32_t i = x + z * 5;
            triangles.push_back({i, i + 5, i + 1});
            triangles.push_back({i + 1, i + 5, i + 6});
        }
    const auto mesh = TriangleMeshShape::Create(vertices, triangles).Value();
    const auto box = BoxShape::Create(Vec3(0.4f, 0.4f, 0.4f)).Value();
    std::mt19937 random(5);
    std::uniform_real_distribution<float> place(0.5f, 3.5f);
    std::vector<Transform> poses;
    for (int i = 0; i < 1000; ++i)
        poses.push_back({Vec3(place(random), 0.39f, place(random)),
                         Quat(Eigen::AngleAxisf(place(random), Vec3::UnitY()))});
    size_t next = 0;
    int64_t manifolds = 0;
    for (auto _ : ioState)
    {
        manifolds +=
            CollideShapes(*box, poses[next], *mesh, Transform::Identity(), {}, [](const ContactManifold&) {});
        next = (next + 1) % poses.size();
    }
    ioState.counters["manifolds_per_call"] = double(manifolds) / double(ioState.iterations());
}

/// The demo's terrain tile: 65 x 65 samples 1 m apart, rolling hills a few metres high.
std::vector<float> TerrainHeights()
{
    std::vector<float> heights;
    for (uint32_t z = 0; z < 65; ++z)
        for (uint32_t x = 0; x < 65; ++x)
            heights.push_back(2.0f * std::sin(0.21f * float(x)) * std::cos(0.17f * float(z)) +
                              0.3f * std::sin(1.3f * float(x + 2 * z)));
    return heights;
}

/// Creating that tile's height field (its edge flags are worked out here, once).
void BM_HeightFieldCreate(benchmark::State& ioState)
{
    const std::vector<float> heights = TerrainHeights();
    for (auto _ : ioState)
    {
        auto field = HeightFieldShape::Create(65, 65, 1.0f, heights);
        benchmark::DoNotOptimize(field);
    }
}

/// A box sunk 5 cm at its centre into that terrain (its corners deeper on a slope), at random places and
/// headings: CollideShapes against the cells under it.
void BM_BoxOnHeightField(benchmark::State& ioState)
{
    const std::vector<float> heights = TerrainHeights();
    const auto field = HeightFieldShape::Create(65, 65, 1.0f, heights).Value();
    const auto box = BoxShape::Create(Vec3(0.4f, 0.4f, 0.4f)).Value();
    std::mt19937 random(5);
    std::uniform_real_distribution<float> place(2.0f, 62.0f), heading(0.0f, 6.28f);
    std::vector<Transform> poses;
    for (int i = 0; i < 1000; ++i)
    {
        const float x = place(random), z = place(random);
        // The height under the box's centre: a ray down the field
        RayHit hit;
        hit.mFraction = 1.0f;
        const RayCast down{Vec3(x, 50.0f, z), Vec3(0.0f, -100.0f, 0.0f)};
        const float y = field->CastRay(down, hit) ? 50.0f - 100.0f * hit.mFraction : 0.0f;
        poses.push_back({Vec3(x, y + 0.35f, z), Quat(Eigen::AngleAxisf(heading(random), Vec3::UnitY()))});
    }
    size_t next = 0;
    int64_t manifolds = 0;
    for (auto _ : ioState)
    {
        manifolds += CollideShapes(*box, poses[next], *field, Transform::Identity(), {},
                                   [](const ContactManifold&) {});
        next = (next + 1) % poses.size();
    }
    ioState.counters["manifolds_per_call"] = double(manifolds) / double(ioState.iterations());
}
} // namespace

BENCHMARK(BM_BoxBox);
BENCHMARK(BM_SphereBox);
BENCHMARK(BM_SphereSphere);
BENCHMARK(BM_BoxOnMesh);
BENCHMARK(BM_HeightFieldCreate);
BENCHMARK(BM_BoxOnHeightField);
BENCHMARK_MAIN();
