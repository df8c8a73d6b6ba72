// The BSP under a BVH8 top (issue #26 step two; bsp-bvh8, bsp-bvh8-float;
// BspTracer::set_bvh8_top, docs/bvh8.md "BSP subtrees below"): the top checks
// itself; with exact leaves the hits equal the exact reference bit for bit on
// random, vertex, edge, stiff rays, lines and segments, for pieces of one
// slot (every leaf cell its own box), of 8 and of 1024 slots; with float
// leaves they equal brute force up to ties; the three kernels agree bit for
// bit; any-hit equals nearest-hit; and node boxes shrunk by one float step
// lose hits, so the bound is not idle.
#include <catch2/catch.hpp>

#include <cstring>
#include <limits>

#include "bsp_test_util.h"
#include "builder/accel_factory.h"
#include "bsprt/compare.h"
#include "bsprt/error.h"
#include "geometry/io/load_mesh.h"
#include "geometry/scenes/default_scene.h"
#include "geometry/scenes/ray_gen.h"
#include "geometry/scenes/stiff_rays.h"
#include "geometry/scenes/stiff_scenes.h"
#include "robust/certified_intersector.h"
#include "robust/exact_tracer.h"
#include "test_util.h"
#include "traverse/embree/bvh8_build.h"

using namespace bsprt;

namespace {

/// Random, vertex, edge and stiff rays, with lines (tnear = -inf) and short segments.
std::vector<Ray> hybrid_rays(const TriangleSoup& soup, std::size_t n) {
  std::vector<Ray> rays;
  for (RaySetKind k : {RaySetKind::Primary, RaySetKind::Random, RaySetKind::Vertex, RaySetKind::Edge}) {
    const std::vector<Ray> r = make_rays(k, soup, n, 21 + std::uint64_t(k));
    rays.insert(rays.end(), r.begin(), r.end());
  }
  const std::size_t base = rays.size();
  const float size = length(soup.bounds().diagonal());
  for (std::size_t i = 0; i + 1 < base; i += 3) {
    Ray line = rays[i];
    line.tnear = -std::numeric_limits<float>::infinity();
    rays.push_back(line);
    Ray seg = rays[i + 1];
    seg.tfar = size / (3.0f * length(seg.dir));
    rays.push_back(seg);
  }
  for (StiffRayKind k : {StiffRayKind::AxisParallel, StiffRayKind::AxisPlane, StiffRayKind::AlongEdge}) {
    const std::vector<Ray> r = stiff_rays(k, soup, n / 4, 41 + std::uint64_t(k));
    rays.insert(rays.end(), r.begin(), r.end());
  }
  return rays;
}

/// Rays whose hit differs from the reference's, in prim or in t.
std::size_t differing(const Accelerator& ref, const Accelerator& t, const std::vector<Ray>& rays) {
  std::size_t bad = 0;
  for (const Ray& r : rays) {
    const Hit a = ref.trace(r), b = t.trace(r);
    bad += (a.prim != b.prim || (a.hit() && a.t != b.t)) ? 1 : 0;
  }
  return bad;
}

/// A BSP tracer of `s` with exact leaves under a BVH8 top of `slots`-slot pieces.
struct ExactHybrid {
  CertifiedIntersector leaf;
  BspTracer bsp;
  ExactHybrid(const test::BspScene& s, std::uint32_t slots) : leaf(s.soup), bsp(s.flat, s.soup) {
    bsp.set_exact_leaf(&leaf);
    add_bvh8_top(bsp, slots);
  }
};

}  // namespace

TEST_CASE("bsp-bvh8: the top is valid, every piece is under it once, and corruption is caught", "[bvh8][bsp]") {
  const test::BspScene s = test::build_bsp_scene(load_mesh(test::scene_path("utah-teapot.obj")));
  BspTracer bsp(s.flat, s.soup);
  for (std::uint32_t slots : {1u, 8u, 1024u}) {
    INFO("slots " << slots);
    const Bvh8Tree t = build_bvh8_over_bsp(bsp, slots);
    REQUIRE_NOTHROW(t.validate());
    CHECK(t.over_bsp);
    const std::vector<BspSubtreeBox> pieces = bsp.subtree_boxes(slots, 4);
    CHECK(t.pieces == pieces.size());
    CHECK(t.pieces > 1);
    // Pieces of one to four distinct triangles become triangle leaves, the rest subtrees.
    std::size_t small = 0;
    for (const BspSubtreeBox& p : pieces) small += p.triangles >= 1 && p.triangles <= 4 ? 1 : 0;
    CHECK(t.subtrees.size() == pieces.size() - small);
    if (slots == 1) CHECK(small > 0);
    if (slots == 1) CHECK(t.subtrees.size() < t.pieces);
    if (slots == 1024) CHECK(t.subtrees.size() > 0);
  }
  const Bvh8Tree good = build_bvh8_over_bsp(bsp, 8);
  REQUIRE(good.subtrees.size() >= 2);
  Bvh8Tree t = good;
  // A subtree referenced twice (and another not at all).
  for (Bvh8Node& n : t.nodes)
    for (std::uint32_t& ref : n.child)
      if (Bvh8Node::is_leaf(ref) && Bvh8Node::count(ref) == Bvh8Node::kSubtree) ref = Bvh8Node::subtree_ref(0);
  CHECK_THROWS_AS(t.validate(), std::logic_error);
  t = good;
  t.pieces += 1;  // a piece missing
  CHECK_THROWS_AS(t.validate(), std::logic_error);
  t = good;
  t.subtrees[0].box.hi.x = 1e30f;  // a subtree outside its slot box
  CHECK_THROWS_AS(t.validate(), std::logic_error);
  t = good;
  t.subtrees[1].slot = std::uint32_t(bsp.compact().slots.size());  // no such slot
  CHECK_THROWS_AS(bsp.set_bvh8_top(std::move(t)), UsageError);
  CHECK_THROWS_AS(bsp.set_bvh8_top(build_bvh8(s.soup)), UsageError);  // not over a BSP
  CHECK_THROWS_AS(build_bvh8_over_bsp(bsp, 0), UsageError);
  // Bvh8Tracer alone cannot trace a top over a BSP (it has no subtrees to run).
  Bvh8Tracer alone(build_bvh8_over_bsp(bsp, 8));
  CHECK_THROWS_AS(alone.trace(Ray{}), UsageError);
}

TEST_CASE("bsp-bvh8: exact leaves equal the exact reference, bit for bit", "[bvh8][bsp]") {
  for (const char* name : {"suzanne.obj", "utah-teapot.obj"}) {
    const test::BspScene s = test::build_bsp_scene(load_mesh(test::scene_path(name)));
    const ExactTracer exact(s.soup);
    const std::vector<Ray> rays = hybrid_rays(s.soup, 800);
    for (std::uint32_t slots : {1u, 8u, 1024u}) {
      const ExactHybrid h(s, slots);
      CHECK(h.bsp.name() == "bsp-bvh8");
      INFO(name << ", slots " << slots << ": " << rays.size() << " rays");
      CHECK(differing(exact, h.bsp, rays) == 0);
    }
  }
  const StiffScene grid = make_stiff_scene("grid_box");
  const test::BspScene s = test::build_bsp_scene(grid.soup);
  const ExactTracer exact(s.soup);
  const ExactHybrid h(s, 8);
  CHECK(differing(exact, h.bsp, hybrid_rays(s.soup, 800)) == 0);
}

TEST_CASE("bsp-bvh8: float leaves equal brute force up to ties", "[bvh8][bsp]") {
  const test::BspScene s = test::build_bsp_scene(load_mesh(test::scene_path("utah-teapot.obj")));
  const BruteForceTracer brute(s.soup);
  const std::vector<Ray> rays = random_rays(s.soup, 3000, 5);
  for (std::uint32_t slots : {1u, 64u}) {
    BspTracer bsp(s.flat, s.soup);
    add_bvh8_top(bsp, slots);
    CHECK(bsp.name() == "bsp-bvh8-float");
    std::vector<Hit> a(rays.size()), b(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) a[i] = brute.trace(rays[i]), b[i] = bsp.trace(rays[i]);
    const HitComparison c = compare_hits(a, b);
    INFO("slots " << slots << ": lost " << c.lost << ", extra " << c.extra << ", farther " << c.farther);
    CHECK(c.agrees());
    CHECK(c.same_triangle > rays.size() / 10);
  }
}

TEST_CASE("bsp-bvh8: the plain x86-64, AVX2 and AVX-512 kernels agree bit for bit, hits and counters",
          "[bvh8][bsp]") {
  const test::BspScene s = test::build_bsp_scene(load_mesh(test::scene_path("suzanne.obj")));
  ExactHybrid base(s, 64), wide(s, 64);  // at 8 slots every piece of suzanne is a triangle leaf
  REQUIRE(base.bsp.bvh8_top()->tree().subtrees.size() > 0);
  base.bsp.set_bvh8_kernel_isa(Isa::Scalar);
  const std::vector<Ray> rays = hybrid_rays(s.soup, 600);
  std::vector<Hit> ref(rays.size());
  RayCounters cr;
  for (std::size_t i = 0; i < rays.size(); ++i) ref[i] = base.bsp.trace(rays[i], &cr);
  CHECK(cr.rays == rays.size());
  CHECK(cr.box_node_visits > 0);
  CHECK(cr.bsp_node_visits + cr.kd_node_visits > 0);  // subtrees were entered
  for (const Isa isa : {Isa::Avx2, Isa::Avx512}) {
    if (int(detected_isa()) < int(isa)) continue;
    wide.bsp.set_bvh8_kernel_isa(isa);
    RayCounters cw;
    std::size_t bad = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Hit h = wide.bsp.trace(rays[i], &cw);
      bad += std::memcmp(&h, &ref[i], sizeof(Hit)) != 0 ? 1 : 0;
    }
    INFO(isa_name(isa));
    CHECK(bad == 0);
    CHECK(cw.box_node_visits == cr.box_node_visits);
    CHECK(cw.bsp_node_visits == cr.bsp_node_visits);
    CHECK(cw.kd_node_visits == cr.kd_node_visits);
    CHECK(cw.triangle_tests == cr.triangle_tests);
  }
  // Counted and uncounted hits are the same.
  std::size_t bad = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Hit h = base.bsp.trace(rays[i]);
    bad += std::memcmp(&h, &ref[i], sizeof(Hit)) != 0 ? 1 : 0;
  }
  CHECK(bad == 0);
}

TEST_CASE("bsp-bvh8: occluded equals trace().hit() and does less work", "[bvh8][bsp]") {
  const TriangleSoup soup = load_mesh(test::scene_path("utah-teapot.obj"));
  const std::vector<Ray> rays = hybrid_rays(soup, 600);
  AccelOptions o;
  o.top_slots = 8;
  for (const char* mode : {"bsp-bvh8", "bsp-bvh8-float"}) {
    const auto t = make_tracer(mode, soup, o);
    CHECK(t->name() == mode);
    RayCounters nearest, any;
    std::size_t differ = 0, hits = 0;
    for (const Ray& r : rays) {
      const bool h = t->trace(r, &nearest).hit();
      differ += h != t->occluded(r, &any) ? 1 : 0;
      hits += h ? 1 : 0;
    }
    INFO(mode << ": " << differ << " of " << rays.size() << " rays differ, " << hits << " hit");
    CHECK(differ == 0);
    CHECK(hits > rays.size() / 4);
    CHECK(any.rays == nearest.rays);
    CHECK(any.box_node_visits < nearest.box_node_visits);
  }
}

// The top's node boxes are exact unions of the pieces' certified boxes, and
// the kernel's box test keeps every point of the exact ray; moving each face
// in by one float step drops points on the faces, where rays through
// vertices hit (the subtrees' own clip still uses the true boxes).
TEST_CASE("bsp-bvh8: node boxes shrunk by one float step lose hits on vertex rays", "[bvh8][bsp]") {
  const test::BspScene s = test::build_bsp_scene(load_mesh(test::scene_path("utah-teapot.obj")));
  const ExactTracer exact(s.soup);
  ExactHybrid tight(s, 1), shrunk(s, 1);
  shrunk.bsp.shrink_bvh8_top_for_testing();
  const std::vector<Ray> rays = vertex_rays(s.soup, 3000, 9);
  const std::size_t bad_tight = differing(exact, tight.bsp, rays), bad_shrunk = differing(exact, shrunk.bsp, rays);
  INFO("differing hits: tight " << bad_tight << ", shrunk " << bad_shrunk << " of " << rays.size());
  CHECK(bad_tight == 0);
  CHECK(bad_shrunk > 0);
}

// The BVH8 kernel cannot take origins beyond 2^126 (p - o could overflow);
// such rays take the plain BSP traversal, still exactly.
TEST_CASE("bsp-bvh8: a ray from beyond 2^126 takes the plain traversal, exactly", "[bvh8][bsp]") {
  const test::BspScene s = test::build_bsp_scene(make_icosphere({0, 0, 0}, 1.0f, 2));
  const ExactTracer exact(s.soup);
  const ExactHybrid h(s, 8);
  Ray r;
  r.org = {0x1p127f, 0.25f, 0.25f};
  r.dir = {-1, 0, 0};
  const Hit e = exact.trace(r), got = h.bsp.trace(r);
  REQUIRE(e.hit());
  CHECK(got.prim == e.prim);
  CHECK(got.t == e.t);
  CHECK(h.bsp.occluded(r));
}
