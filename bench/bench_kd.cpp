// bench_kd: the SAH kd-tree against Embree 3 (robust mode), measured in the
// same run on the same rays: build seconds, Mrays/s for primary (1024x768
// camera framing the mesh) and random rays, single rays and packets of the
// widest ISA, and kd work per ray. All threads (tbb::parallel_for over blocks).
//
//   bench_kd [--scenes DIR] [--runs N] [--random N] [mesh files...]
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/combinable.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>

#include "apps/bench_runner.h"
#include "builder/kd/kd_build.h"
#include "geometry/scenes/camera.h"
#include "geometry/io/load_mesh.h"
#include "geometry/scenes/ray_gen.h"
#include "traverse/simd/cpu_features.h"
#include "traverse/embree/embree_tracer.h"
#include "traverse/kd/kd_traverse.h"

using namespace bsprt;

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

struct RaySet {
  std::string name;
  std::vector<Ray> rays;
};

void bench_scene(const std::string& path, int runs, std::size_t n_random, int width) {
  const TriangleSoup soup = load_mesh(path);
  const std::string name = path.substr(path.find_last_of('/') + 1);
  KdBuildReport report;
  auto t0 = Clock::now();
  const KdTracer kd(build_kd(soup, {}, &report), soup);
  const double kd_build = seconds_since(t0);
  t0 = Clock::now();
  const EmbreeTracer embree(soup);
  const double embree_build = seconds_since(t0);
  fmt::print("\n## {} ({} triangles)\n\n", name, soup.size());
  fmt::print("build: kd {:.3f} s, Embree {:.3f} s (ratio {:.2f}); kd: {} nodes, {} leaves ({} empty), "
             "{:.2f} tris/leaf, depth {} (limit {}), {:.1f} MB\n\n",
             kd_build, embree_build, kd_build / embree_build, report.nodes, report.leaves,
             report.empty_leaves, report.avg_leaf_size, report.max_depth, report.depth_limit,
             double(kd.memory_bytes()) / 1e6);
  const std::vector<RaySet> sets = {{"primary", tiled_primary_rays(frame_bounds(soup.bounds()), 1024, 768)},
                                    {"random", random_rays(soup, n_random, 1)}};
  fmt::print("| rays | mode | kd Mrays/s | Embree Mrays/s | kd time / Embree time | kd node visits/ray | kd tri tests/ray |\n");
  fmt::print("|---|---|---:|---:|---:|---:|---:|\n");
  for (const RaySet& set : sets) {
    const RayCounters c = count_work(kd, set.rays);
    const double n = double(set.rays.size());
    const std::vector<int> modes = width == 1 ? std::vector<int>{1} : std::vector<int>{1, width};
    for (int w : modes) {
      std::vector<Hit> hits;
      const double tk = time_trace(kd, set.rays, hits, w, runs), te = time_trace(embree, set.rays, hits, w, runs);
      fmt::print("| {} | {} | {:.2f} | {:.2f} | {:.2f} | {:.1f} | {:.1f} |\n", set.name,
                 w == 1 ? std::string("single") : fmt::format("packet {}", w), n / tk / 1e6,
                 n / te / 1e6, tk / te, double(c.kd_node_visits) / n, double(c.triangle_tests) / n);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string dir = BSPRT_SCENES_DIR;
  int runs = 3;
  std::size_t n_random = 1u << 20;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--scenes" && i + 1 < argc) dir = argv[++i];
    else if (a == "--runs" && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
    else if (a == "--random" && i + 1 < argc) n_random = std::size_t(std::atoll(argv[++i]));
    else files.push_back(a);
  }
  if (files.empty())
    files = {dir + "/stanford-bunny.obj", dir + "/stanford-dragon-100k.ply", dir + "/happy-buddha-res4.ply"};
  const Isa isa = detected_isa();
  fmt::print("# bench_kd: kd-tree vs Embree 3 (robust), {} threads, widest ISA {} (packets of {}), best of {} runs\n",
             tbb::info::default_concurrency(), isa_name(isa), isa_width(isa), runs);
  try {
    for (const std::string& f : files) bench_scene(f, runs, n_random, isa_width(isa));
  } catch (const std::exception& e) {
    fmt::print(stderr, "bench_kd: {}\n", e.what());
    return 1;
  }
  return 0;
}
