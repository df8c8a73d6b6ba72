// bench_bsp_build: exact BSP build times and tree figures (docs/bsp-build.md),
// with the kd-tree's build time on the same scene in the same run.
//
//   bench_bsp_build [options] [scene ...]      (default: suzanne, teapot, bunny)
//     --threads N          worker threads (0 = all cores)
//     --area               BspMembership::Area instead of Closed
//     --coplanar-one-side  coplanar triangles to the cheaper side only
//     --bsp-max N          BspConfig::bsp_max_triangles
//     --bsh-min N          BspConfig::bsh_min_triangles
//     --kd-only            no face/edge candidates
//     --min-gain X         BspConfig::min_gain
//     --max-depth N        BspConfig::max_depth
//     --bsh-scaling        count with and without the BSH on growing spheres
#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "builder/bsp/bsp_build.h"
#include "builder/kd/kd_build.h"
#include "geometry/io/load_mesh.h"

namespace {

using namespace bsprt;

void print_report(const std::string& name, std::size_t tris, const BspBuildReport& r, double kd_seconds) {
  fmt::print("\n== {} ({} triangles, {} degenerate left out)\n", name, tris, r.degenerate);
  fmt::print("build {:.2f} s ({:.0f} tri/s); kd-tree build in the same run {:.2f} s\n", r.seconds,
             double(tris) / r.seconds, kd_seconds);
  fmt::print("nodes {}  leaves {} (empty {})  kd splits {}  BSP splits {}  max depth {}  depth-limited {}\n",
             r.nodes, r.leaves, r.empty_leaves, r.kd_splits, r.bsp_splits, r.max_depth, r.depth_limited);
  fmt::print("triangle refs {} ({:.2f} per non-empty leaf)  SAH cost {:.1f}  failed split attempts {}\n",
             r.triangle_refs, double(r.triangle_refs) / double(std::max<std::size_t>(1, r.leaves - r.empty_leaves)),
             r.sah_cost, r.failed_split_attempts);
  fmt::print("side tests: interval {}  symbolic {}  exact fallbacks {}  exact point enclosures {}\n",
             r.exact.filter_calls, r.exact.symbolic, r.exact.exact_fallbacks, r.exact.exact_points);
  fmt::print("leaf histogram (triangles: leaves):");
  for (std::size_t i = 0; i < r.leaf_histogram.size(); ++i)
    if (r.leaf_histogram[i] && (i <= 12 || r.leaf_histogram[i] > 0)) fmt::print(" {}:{}", i, r.leaf_histogram[i]);
  fmt::print("\nsplits by depth (depth: kd/BSP):");
  const std::size_t depth = std::max(r.kd_by_depth.size(), r.bsp_by_depth.size());
  for (std::size_t d = 0; d < depth; ++d) {
    const std::size_t k = d < r.kd_by_depth.size() ? r.kd_by_depth[d] : 0;
    const std::size_t b = d < r.bsp_by_depth.size() ? r.bsp_by_depth[d] : 0;
    fmt::print(" {}:{}/{}", d, k, b);
  }
  fmt::print("\n");
}

TriangleSoup uv_sphere(int rings, int segments) {
  TriangleSoup s;
  auto p = [&](int i, int j) {
    const double th = M_PI * i / rings, ph = 2 * M_PI * j / segments;
    return Vec3f(float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)), float(std::cos(th)));
  };
  auto tri = [&](Vec3f a, Vec3f b, Vec3f c) {
    const auto i = std::uint32_t(s.vertices.size());
    s.vertices.insert(s.vertices.end(), {a, b, c});
    s.triangles.push_back({i, i + 1, i + 2});
  };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      if (i != rings - 1) tri(p(i, j), p(i + 1, j), p(i + 1, j + 1));
      if (i != 0) tri(p(i, j), p(i + 1, j + 1), p(i, j + 1));
    }
  return s;
}

/// The paper's full BSP (face/edge candidates at every node) on growing spheres,
/// counted with a flat sphere list (naive O(N) per candidate) and with the BSH.
void bsh_scaling(BspConfig cfg) {
  cfg.bsp_max_triangles = SIZE_MAX;
  cfg.kd_candidates = false;
  fmt::print("full BSP (face+edge candidates at every node), single thread\n");
  fmt::print("{:>8} {:>12} {:>12} {:>8}\n", "tris", "naive s", "BSH s", "ratio");
  for (int rings : {8, 16, 24, 32, 48}) {
    const TriangleSoup s = uv_sphere(rings, 2 * rings);
    cfg.threads = 1;
    BspBuildReport naive, bsh;
    cfg.bsh_min_triangles = SIZE_MAX;
    build_bsp(s, cfg, &naive);
    cfg.bsh_min_triangles = 16;
    build_bsp(s, cfg, &bsh);
    fmt::print("{:>8} {:>12.3f} {:>12.3f} {:>8.2f}\n", s.size(), naive.seconds, bsh.seconds,
               naive.seconds / bsh.seconds);
  }
}

}  // namespace

int main(int argc, char** argv) {
  BspConfig cfg;
  std::vector<std::string> scenes;
  bool scaling = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string("0"); };
    if (a == "--threads") cfg.threads = std::stoi(next());
    else if (a == "--area") cfg.membership = BspMembership::Area;
    else if (a == "--coplanar-one-side") cfg.coplanar_to_both = false;
    else if (a == "--bsp-max") cfg.bsp_max_triangles = std::stoull(next());
    else if (a == "--bsh-min") cfg.bsh_min_triangles = std::stoull(next());
    else if (a == "--min-gain") cfg.min_gain = std::stod(next());
    else if (a == "--max-depth") cfg.max_depth = std::stoi(next());
    else if (a == "--kd-only") cfg.face_candidates = cfg.edge_candidates = false;
    else if (a == "--bsh-scaling") scaling = true;
    else scenes.push_back(a);
  }
  if (scaling) {
    bsh_scaling(cfg);
    return 0;
  }
  if (scenes.empty())
    for (const char* s : {"suzanne.obj", "utah-teapot.obj", "stanford-bunny.obj"})
      scenes.push_back(std::string(BSPRT_SCENES_DIR) + "/" + s);
  for (const std::string& path : scenes) {
    const TriangleSoup soup = load_mesh(path);
    KdBuildReport kd;
    build_kd(soup, {}, &kd);
    BspBuildReport r;
    build_bsp(soup, cfg, &r);
    print_report(path, soup.size(), r, kd.seconds);
  }
  return 0;
}
