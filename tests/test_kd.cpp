// The SAH kd-tree (builder/kd_build.h, traverse/kd_traverse.h) against brute
// force on shared meshes and generated stiff cases: same nearest hit (a
// different triangle only at a tie of t), no lost hit; packets equal single
// rays bit for bit; exact coverage check of the tree; tree files.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "builder/accel_factory.h"
#include "builder/kd/kd_build.h"
#include "builder/kd/kd_file.h"
#include "bsprt/error.h"
#include "geometry/io/load_mesh.h"
#include "geometry/scenes/ray_gen.h"
#include "robust/certified_intersector.h"
#include "robust/degenerate.h"
#include "test_util.h"
#include "traverse/brute_force.h"
#include "traverse/simd/cpu_features.h"
#include "traverse/kd/kd_traverse.h"
#include "traverse/simd/watertight_packet_brute.h"

using namespace bsprt;

namespace {

/// Brute-force reference in the widest native packets (equal to single rays).
std::vector<Hit> brute_hits(const TriangleSoup& s, const std::vector<Ray>& rays) {
  std::vector<Hit> hits(rays.size());
  brute_force_trace_batch(s, rays, hits, isa_width(detected_isa()), nullptr);
  return hits;
}

/// Ray by ray: both miss, or both hit at the same t (1e-6 relative), with the
/// same triangle unless it is a tie. Returns the number of disagreements.
std::size_t compare_hits(const std::vector<Hit>& ref, const std::vector<Hit>& got, const std::string& what) {
  std::size_t bad = 0, ties = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    const Hit &a = ref[i], &b = got[i];
    if (!a.hit() && !b.hit()) continue;
    const bool same_t = a.hit() && b.hit() && std::abs(a.t - b.t) <= 1e-6f * std::abs(a.t);
    ties += same_t && a.prim != b.prim;
    if (!same_t) {
      if (bad < 5)
        UNSCOPED_INFO(what << " ray " << i << ": brute t=" << a.t << " prim=" << a.prim << ", kd t=" << b.t
                           << " prim=" << b.prim);
      ++bad;
    }
  }
  UNSCOPED_INFO(what << ": " << ref.size() << " rays, " << ties << " ties, " << bad << " disagreements");
  return bad;
}

std::vector<Hit> kd_hits(const KdTracer& kd, const std::vector<Ray>& rays, int width = 1,
                         RayCounters* c = nullptr) {
  std::vector<Hit> hits(rays.size());
  kd.trace_batch(rays, hits, width, c);
  return hits;
}

/// Packets of every supported width give bit-identical hits and equal counters.
void check_packets(const KdTracer& kd, const std::vector<Ray>& rays) {
  RayCounters c1;
  const std::vector<Hit> single = kd_hits(kd, rays, 1, &c1);
  for (int w : {4, 8, 16}) {
    if (int(detected_isa()) < int(isa_for_width(w))) continue;
    RayCounters cw;
    const std::vector<Hit> packed = kd_hits(kd, rays, w, &cw);
    std::size_t diff = 0;
    for (std::size_t i = 0; i < rays.size(); ++i)
      diff += std::memcmp(&single[i], &packed[i], sizeof(Hit)) != 0;
    INFO("packet width " << w);
    CHECK(diff == 0);
    CHECK(cw.rays == c1.rays);
    CHECK(cw.kd_node_visits == c1.kd_node_visits);
    CHECK(cw.leaf_visits == c1.leaf_visits);
    CHECK(cw.triangle_tests == c1.triangle_tests);
    const std::vector<Hit> uncounted = kd_hits(kd, rays, w, nullptr);
    CHECK(std::memcmp(uncounted.data(), packed.data(), packed.size() * sizeof(Hit)) == 0);
  }
}

/// Axis-aligned rays through the corners of random triangles (zero direction
/// components; origins on the vertex in two coordinates).
std::vector<Ray> axis_rays(const TriangleSoup& s, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  const Box3f b = s.bounds();
  std::vector<Ray> rays;
  while (rays.size() < n) {
    const std::uint32_t t = std::uint32_t(g() % s.size());
    if (s.is_degenerate(t)) continue;
    const Vec3f p = s.corner(t, int(g() % 3));
    const int k = int(g() % 3);
    const bool neg = g() & 1;
    Ray r;
    r.org = p;
    r.org[k] = neg ? b.hi[k] + 1.0f : b.lo[k] - 1.0f;
    r.dir[k] = neg ? -1.0f : 1.0f;
    if (g() & 1) r.dir[(k + 1) % 3] = -0.0f;  // signed zeros
    rays.push_back(r);
  }
  return rays;
}

/// Rays lying in the kd-tree's split planes: origin on the plane, zero
/// direction component across it.
std::vector<Ray> split_plane_rays(const KdTree& tree, const TriangleSoup& s, std::size_t n,
                                  std::uint64_t seed) {
  std::vector<std::pair<int, float>> planes;
  for (const KdNode& node : tree.nodes)
    if (!node.is_leaf()) planes.push_back({node.axis(), node.split});
  std::vector<Ray> rays = random_rays(s, n, seed);
  if (planes.empty()) return rays;
  std::mt19937_64 g(seed);
  for (Ray& r : rays) {
    const auto [k, split] = planes[g() % planes.size()];
    r.org[k] = split;
    r.dir[k] = (g() & 1) ? 0.0f : -0.0f;
    if (r.dir == Vec3f{}) r.dir[(k + 1) % 3] = 1.0f;
  }
  return rays;
}

/// Builds, validates (structure and exact coverage) and compares with brute
/// force on random, primary, vertex-, edge-aimed, axis and split-plane rays.
void check_scene(const TriangleSoup& soup, const std::string& name, std::size_t n, bool coverage = true,
                 const KdConfig& config = {}) {
  INFO("scene " << name);
  KdBuildReport report;
  KdTree tree = build_kd(soup, config, &report);
  REQUIRE_NOTHROW(tree.validate());
  if (coverage) REQUIRE_NOTHROW(validate_kd_coverage(tree, soup));
  for (std::uint32_t p : tree.prims) REQUIRE_FALSE(soup.is_degenerate(p));
  const KdTracer kd(tree, soup);
  const std::vector<std::pair<std::string, std::vector<Ray>>> sets = {
      {"random", random_rays(soup, n, 1)},
      {"primary", make_rays(RaySetKind::Primary, soup, n, 2)},
      {"vertex", vertex_rays(soup, n, 3)},
      {"edge", edge_rays(soup, n, 4)},
      {"axis", axis_rays(soup, n / 2, 5)},
      {"split-plane", split_plane_rays(tree, soup, n / 2, 6)},
  };
  for (const auto& [what, rays] : sets) {
    CHECK(compare_hits(brute_hits(soup, rays), kd_hits(kd, rays), name + " " + what) == 0);
    check_packets(kd, rays);
  }
  // The same tree with the exact leaf test (the default "kd"): hits equal the
  // exact reference's, prim and t, on every set (at most 4,000 rays of each),
  // one ray at a time and in packets.
  KdTracer exact_kd(tree, soup);
  const CertifiedIntersector leaf(soup);
  exact_kd.set_exact_leaf(&leaf);
  REQUIRE(exact_kd.name() == "kd");
  const std::unique_ptr<Accelerator> reference = make_tracer("exact", soup);
  for (const auto& [what, all] : sets) {
    const std::vector<Ray> rays(all.begin(), all.begin() + std::ptrdiff_t(std::min<std::size_t>(all.size(), 4000)));
    std::vector<Hit> want(rays.size());
    reference->trace_batch(rays, want, 1);
    const std::vector<Hit> got = kd_hits(exact_kd, rays);
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < rays.size(); ++i)
      wrong += got[i].prim != want[i].prim || (want[i].hit() && got[i].t != want[i].t);
    INFO("exact leaves, " << what);
    CHECK(wrong == 0);
    check_packets(exact_kd, rays);
  }
  // On rays that hit nothing no cull bound ever applies, so exact and float
  // leaves walk the same nodes and leaves, empty leaves included (the exact
  // path skips the leaf test of an empty leaf but still counts the visit),
  // and test the same triangles.
  std::vector<Ray> misses;
  for (const auto& [what, all] : sets) {
    const std::vector<Hit> f = kd_hits(kd, all), e = kd_hits(exact_kd, all);
    for (std::size_t i = 0; i < all.size() && misses.size() < 4000; ++i)
      if (!f[i].hit() && !e[i].hit()) misses.push_back(all[i]);
  }
  CHECK(misses.size() >= 100);
  RayCounters float_count, exact_count;
  kd_hits(kd, misses, 1, &float_count);
  kd_hits(exact_kd, misses, 1, &exact_count);
  CHECK(exact_count.leaf_visits == float_count.leaf_visits);
  CHECK(exact_count.kd_node_visits == float_count.kd_node_visits);
  CHECK(exact_count.triangle_tests == float_count.triangle_tests);
  // Switched off, the leaves are float again: the float tracer's hits, bit for bit.
  exact_kd.set_exact_leaf(nullptr);
  CHECK(exact_kd.name() == "kd-float");
  const std::vector<Ray>& some = sets.front().second;
  CHECK(std::memcmp(kd_hits(exact_kd, some).data(), kd_hits(kd, some).data(), some.size() * sizeof(Hit)) == 0);
}

TriangleSoup load(const std::string& file) { return load_mesh(test::scene_path(file)); }

void add_triangle(TriangleSoup& s, Vec3f a, Vec3f b, Vec3f c) {
  const auto i = std::uint32_t(s.vertices.size());
  s.vertices.insert(s.vertices.end(), {a, b, c});
  s.triangles.push_back({i, i + 1, i + 2});
}

/// Stacks of axis-aligned coplanar triangles: many triangles in each plane
/// x = c, y = c, z = c (overlapping, duplicated), plus a few slanted ones.
TriangleSoup coplanar_stacks() {
  TriangleSoup s;
  std::mt19937 g(7);
  std::uniform_real_distribution<float> u(0.0f, 4.0f);
  for (int k = 0; k < 3; ++k) {
    for (float c : {0.0f, 1.0f, 1.5f, 2.0f, 4.0f}) {
      for (int i = 0; i < 40; ++i) {
        Vec3f p[3];
        for (Vec3f& v : p) {
          v = {u(g), u(g), u(g)};
          v[k] = c;
        }
        add_triangle(s, p[0], p[1], p[2]);
        if (i % 5 == 0) add_triangle(s, p[0], p[1], p[2]);  // exact duplicate
      }
    }
  }
  for (int i = 0; i < 50; ++i) add_triangle(s, {u(g), u(g), u(g)}, {u(g), u(g), u(g)}, {u(g), u(g), u(g)});
  add_triangle(s, {1, 1, 1}, {1, 1, 1}, {2, 2, 2});  // degenerate: never hit, never listed
  classify_degenerate(s);
  return s;
}

/// A grid of unit cubes (12 triangles each) sharing faces: every face lies in
/// a plane the SAH likes to split at.
TriangleSoup cube_grid(int n) {
  TriangleSoup s;
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y)
      for (int z = 0; z < n; ++z) {
        const Vec3f o{float(x), float(y), float(z)};
        for (int k = 0; k < 3; ++k)
          for (float side : {0.0f, 1.0f}) {
            const int i = (k + 1) % 3, j = (k + 2) % 3;
            Vec3f a = o, b = o, c = o, d = o;
            a[k] = b[k] = c[k] = d[k] = o[k] + side;
            b[i] += 1, c[i] += 1, c[j] += 1, d[j] += 1;
            add_triangle(s, a, b, c);
            add_triangle(s, a, c, d);
          }
      }
  classify_degenerate(s);
  return s;
}

}  // namespace

TEST_CASE("kd-tree equals brute force on shared meshes", "[kd]") {
  for (const char* file : {"cube.obj", "suzanne.obj", "utah-teapot.obj", "stiff_planexy.off",
                           "stiff_cube_with_fold.ply", "stiff_degenerated.obj",
                           "stiff_two-boxes-bad-self-union.ply", "stiff_sliver_tet.ply"})
    check_scene(load(file), file, 4000);
}

TEST_CASE("kd-tree equals brute force on the bunny", "[kd][slow]") {
  check_scene(load("stanford-bunny.obj"), "bunny", 20000, /*coverage=*/true);
}

// Regression: planes one float off the stack at x = 0 were denormal (1.4e-45);
// rays lying in them made the watertight test underflow and hit the stack,
// which the kd-tree (exactly) had not listed in their cells.
TEST_CASE("kd-tree on coplanar stacks, split-plane triangles and rays", "[kd][stiff]") {
  const TriangleSoup s = coplanar_stacks();
  check_scene(s, "coplanar stacks", 6000);
  // Some split planes hold triangles lying in them (the p-/p+ choice was used).
  const KdTree tree = build_kd(s);
  std::set<std::pair<int, float>> planes;
  for (const KdNode& n : tree.nodes)
    if (!n.is_leaf()) planes.insert({n.axis(), n.split});
  std::size_t in_plane = 0;
  for (std::uint32_t t = 0; t < s.size(); ++t) {
    const auto c = s.corners(t);
    for (int k = 0; k < 3; ++k)
      in_plane += c[0][k] == c[1][k] && c[1][k] == c[2][k] && planes.count({k, c[0][k]});
  }
  CHECK(in_plane > 0);
  const TriangleSoup grid = cube_grid(4);
  check_scene(grid, "cube grid", 6000);
  KdConfig no_clip;
  no_clip.perfect_splits = false;
  check_scene(grid, "cube grid, no perfect splits", 2000, true, no_clip);
  KdConfig deep;
  deep.leaf_size = 0;
  deep.traversal_cost = 1.0f;  // split as much as the depth limit allows
  check_scene(s, "coplanar stacks, split to the depth limit", 3000, true, deep);
}

TEST_CASE("kd build report and empty scenes", "[kd]") {
  const TriangleSoup s = load("suzanne.obj");
  KdBuildReport r;
  const KdTree tree = build_kd(s, {}, &r);
  const KdTreeStats st = kd_tree_stats(tree);
  CHECK(r.nodes == tree.nodes.size());
  CHECK(r.leaves == st.leaves);
  CHECK(r.nodes == 2 * r.leaves - 1);
  CHECK(r.bytes == tree.memory_bytes());
  CHECK(r.max_depth <= r.depth_limit);
  CHECK(r.avg_leaf_size > 0);

  const TriangleSoup empty;
  const KdTree et = build_kd(empty);
  REQUIRE(et.nodes.size() == 1);
  const KdTracer ek(et, empty);
  Ray ray;
  ray.dir = {0, 0, 1};
  CHECK_FALSE(ek.trace(ray).hit());
}

TEST_CASE("kd single rays: invalid rays, tnear/tfar, counters", "[kd]") {
  const TriangleSoup s = load("cube.obj");
  const KdTracer kd(build_kd(s), s);
  const BruteForceTracer brute(s);
  Ray r;
  r.org = {0, 0, -5};
  r.dir = {0, 0, 1};
  RayCounters c;
  const Hit h = kd.trace(r, &c);
  CHECK(h.hit());
  CHECK(h.t == brute.trace(r).t);
  CHECK(c.rays == 1);
  CHECK(c.triangle_tests > 0);
  CHECK(c.leaf_visits > 0);
  r.tfar = 1.0f;  // ends before the cube
  CHECK_FALSE(kd.trace(r).hit());
  r.tfar = std::numeric_limits<float>::infinity();
  r.tnear = -100.0f;  // the segment reaches behind the origin
  CHECK(kd.trace(r).t == brute.trace(r).t);
  r.dir = {0, 0, 0};
  CHECK_FALSE(kd.trace(r).hit());
  r.dir = {std::numeric_limits<float>::quiet_NaN(), 0, 1};
  CHECK_FALSE(kd.trace(r).hit());
  std::vector<Ray> rays(3);
  std::vector<Hit> hits(2);
  CHECK_THROWS_AS(kd.trace_batch(rays, hits, 1), UsageError);
  hits.resize(3);
  CHECK_THROWS_AS(kd.trace_batch(rays, hits, 3), UsageError);
}

TEST_CASE("kd tree files: round trip, corrupt, truncated, wrong scene", "[kd][file]") {
  const TriangleSoup s = load("utah-teapot.obj");
  KdConfig cfg;
  cfg.empty_bonus = 0.75f;
  const KdTree tree = build_kd(s, cfg);
  const std::string path = test::temp_path("teapot.kdtree");
  write_kd_tree(path, tree, s, cfg);

  KdConfig back;
  const KdTree read = read_kd_tree(path, s, &back);
  CHECK(back.empty_bonus == 0.75f);
  CHECK(read.prims == tree.prims);
  REQUIRE(read.nodes.size() == tree.nodes.size());
  CHECK(std::memcmp(read.nodes.data(), tree.nodes.data(), tree.nodes.size() * sizeof(KdNode)) == 0);
  CHECK(read.bounds.lo == tree.bounds.lo);
  CHECK(read.bounds.hi == tree.bounds.hi);

  AccelOptions opt;
  opt.tree_path = path;
  CHECK(make_tracer("kd", s, opt)->name() == "kd");  // exact leaves, from the same file
  const auto from_file = make_tracer("kd-float", s, opt);
  CHECK(from_file->name() == "kd-float");
  const std::vector<Ray> rays = random_rays(s, 500, 9);
  CHECK(compare_hits(brute_hits(s, rays), kd_hits(static_cast<const KdTracer&>(*from_file), rays), "file") == 0);

  std::vector<char> bytes(std::filesystem::file_size(path));
  std::ifstream(path, std::ios::binary).read(bytes.data(), std::streamsize(bytes.size()));
  auto write_bytes = [](const std::string& p, const std::vector<char>& b) {
    std::ofstream(p, std::ios::binary).write(b.data(), std::streamsize(b.size()));
  };
  auto expect_input_error = [&](const std::string& p, const TriangleSoup& scene, const std::string& what) {
    INFO(what);
    try {
      read_kd_tree(p, scene);
      FAIL("no InputError");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find(p) != std::string::npos);
    }
  };
  for (std::size_t at : {std::size_t(9), std::size_t(20), std::size_t(36), std::size_t(60), bytes.size() / 2,
                         bytes.size() - 1}) {
    std::vector<char> bad = bytes;
    bad[at] ^= 0x10;
    const std::string p = test::temp_path("corrupt.kdtree");
    write_bytes(p, bad);
    expect_input_error(p, s, "flipped byte " + std::to_string(at));
  }
  for (std::size_t len : {std::size_t(0), std::size_t(20), std::size_t(44), bytes.size() - 8}) {
    const std::string p = test::temp_path("truncated.kdtree");
    write_bytes(p, std::vector<char>(bytes.begin(), bytes.begin() + std::ptrdiff_t(len)));
    expect_input_error(p, s, "truncated to " + std::to_string(len));
  }
  expect_input_error(path, load("suzanne.obj"), "another scene");
  TriangleSoup moved = s;
  moved.vertices[0].x += 0.5f;  // same triangle count, other geometry
  expect_input_error(path, moved, "moved vertex");
  expect_input_error(test::temp_path("does-not-exist.kdtree"), s, "missing file");
  CHECK_THROWS_AS(make_tracer("kd", load("suzanne.obj"), opt), InputError);
}

TEST_CASE("accel factory", "[kd]") {
  const TriangleSoup s = load("suzanne.obj");
  for (const std::string& name : accel_names()) {
    const auto t = make_tracer(name, s);
    CHECK(t->name() == name);  // --accel names and tracer names are one vocabulary
  }
  CHECK_THROWS_AS(make_tracer("octree", s), UsageError);
  AccelOptions threads;
  threads.threads = 1;
  CHECK(make_tracer("kd", s, threads)->memory_bytes() > 0);
}
