// bench_micro: Google Benchmark micro-benchmarks of the per-ray building
// blocks, to turn per-ray counters into time (docs/notes/2026-11-22-face-hits.md):
//
//   BM_WatertightHit    the watertight test of a primary ray against the
//                       triangle it hits (a leaf test that finds the hit)
//   BM_WatertightMiss   the same rays against the next triangle of the mesh
//                       (mostly a near miss, the usual extra leaf test)
//   BM_WatertightSetup  the per-ray shear precomputation
//
//   bench_micro [--benchmark_* flags]       scene: BSPRT_SCENE or the bunny
// Rays are 2^16 primary rays of bsprt's default camera; hits come from a kd-tree
// built in the same run. Items per second = tests (or rays) per second.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "builder/kd/kd_build.h"
#include "geometry/io/load_mesh.h"
#include "geometry/scenes/ray_gen.h"
#include "traverse/kd/kd_traverse.h"
#include "traverse/watertight.h"

namespace {

using namespace bsprt;

/// The scene, its primary rays and, for each ray that hits, the ray's shear
/// and the triangle it hits.
struct Fixture {
  TriangleSoup soup;
  std::vector<Ray> rays;
  std::vector<WatertightRay> hit_rays;
  std::vector<std::uint32_t> hit_prims;

  Fixture() {
    const char* env = std::getenv("BSPRT_SCENE");
    soup = load_mesh(env ? std::string(env) : std::string(BSPRT_SCENES_DIR) + "/stanford-bunny.obj");
    rays = make_rays(RaySetKind::Primary, soup, std::size_t(1) << 16, 1);
    const KdTracer kd(build_kd(soup), soup);
    for (const Ray& r : rays) {
      const Hit h = kd.trace(r);
      if (!h.hit()) continue;
      hit_rays.push_back(watertight_precompute(r));
      hit_prims.push_back(h.prim);
    }
  }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

void run_pairs(benchmark::State& state, std::uint32_t offset) {
  const Fixture& f = fixture();
  const std::size_t n = f.hit_rays.size();
  if (n == 0) {
    state.SkipWithError("no ray hits the scene");
    return;
  }
  std::size_t hits = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t p = std::uint32_t((f.hit_prims[i] + offset) % f.soup.size());
      Hit h;
      const auto c = f.soup.corners(p);
      hits += intersect_watertight_closest(f.hit_rays[i], c[0], c[1], c[2], p, h);
      benchmark::DoNotOptimize(h);
    }
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(n));
  state.counters["hit_fraction"] = double(hits) / double(state.iterations() * n);
}

void BM_WatertightHit(benchmark::State& state) { run_pairs(state, 0); }
void BM_WatertightMiss(benchmark::State& state) { run_pairs(state, 1); }

void BM_WatertightSetup(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state)
    for (const Ray& r : f.rays) benchmark::DoNotOptimize(watertight_precompute(r));
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(f.rays.size()));
}

BENCHMARK(BM_WatertightHit);
BENCHMARK(BM_WatertightMiss);
BENCHMARK(BM_WatertightSetup);

}  // namespace

BENCHMARK_MAIN();
