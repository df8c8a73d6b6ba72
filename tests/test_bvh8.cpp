// The plain BVH8 and its Embree-style single-ray kernel (issue #26, step one;
// traverse/bvh/, docs/bvh8.md): the tree checks itself; with exact leaves the
// hits equal the exact reference bit for bit on random, vertex, edge and
// stiff rays, lines (tnear < 0) and short segments; with float leaves (the
// four-lane block test) they equal brute force's scalar test, bit for bit on
// the same triangle; the plain x86-64, AVX2 and AVX-512 kernels agree; and boxes
// shrunk by one float step lose hits, so the tight boxes and the conservative
// box test are what keeps them.
#include <catch2/catch.hpp>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "builder/accel_factory.h"
#include "bsprt/compare.h"
#include "bsprt/error.h"
#include "geometry/io/load_mesh.h"
#include "geometry/scenes/default_scene.h"
#include "geometry/scenes/ray_gen.h"
#include "geometry/scenes/stiff_rays.h"
#include "geometry/scenes/stiff_scenes.h"
#include "robust/certified_intersector.h"
#include "robust/degenerate.h"
#include "robust/exact_tracer.h"
#include "test_util.h"
#include "traverse/brute_force.h"
#include "traverse/bvh/bvh8_traverse.h"
#include "traverse/embree/bvh8_build.h"
#include "traverse/exact_prefilter.h"

using namespace bsprt;

namespace {

struct Scene {
  std::string name;
  TriangleSoup soup;
};

std::vector<Scene> scenes() {
  std::vector<Scene> s;
  s.push_back({"suzanne", load_mesh(test::scene_path("suzanne.obj"))});
  s.push_back({"teapot", load_mesh(test::scene_path("utah-teapot.obj"))});
  s.push_back({"icosphere(5120)", make_icosphere({0.5f, -0.25f, 2}, 1.0f, 4)});
  s.push_back({"ground(2048)", make_ground({0, 0, 0}, 1.0f, 32)});
  s.push_back({"grid_box", make_stiff_scene("grid_box").soup});
  return s;
}

/// Random, vertex and edge rays, the same as lines (tnear = -inf) and as short
/// segments (tfar at a third of the scene's size).
std::vector<Ray> test_rays(const TriangleSoup& soup, std::size_t n) {
  std::vector<Ray> rays;
  for (RaySetKind k : {RaySetKind::Random, RaySetKind::Vertex, RaySetKind::Edge}) {
    const std::vector<Ray> r = make_rays(k, soup, n, 11 + std::uint64_t(k));
    rays.insert(rays.end(), r.begin(), r.end());
  }
  const std::size_t base = rays.size();
  const float size = length(soup.bounds().diagonal());
  for (std::size_t i = 0; i < base; i += 3) {
    Ray line = rays[i];
    line.tnear = -std::numeric_limits<float>::infinity();
    rays.push_back(line);
    Ray seg = rays[i + 1];
    seg.tfar = size / (3.0f * length(seg.dir));
    rays.push_back(seg);
  }
  for (StiffRayKind k : {StiffRayKind::AxisParallel, StiffRayKind::AxisPlane, StiffRayKind::AlongEdge}) {
    const std::vector<Ray> r = stiff_rays(k, soup, n / 4, 31 + std::uint64_t(k));
    rays.insert(rays.end(), r.begin(), r.end());
  }
  return rays;
}

std::unique_ptr<Accelerator> exact_bvh8(const TriangleSoup& soup) { return make_tracer("bvh8", soup); }

/// Rays whose hit differs from the reference's, in prim or in t.
std::size_t differing(const Accelerator& ref, const Accelerator& t, const std::vector<Ray>& rays) {
  std::size_t bad = 0;
  for (const Ray& r : rays) {
    const Hit a = ref.trace(r), b = t.trace(r);
    bad += (a.prim != b.prim || (a.hit() && a.t != b.t)) ? 1 : 0;
  }
  return bad;
}

}  // namespace

TEST_CASE("bvh8: the tree is valid, holds every usable triangle and catches corruption", "[bvh8]") {
  for (const Scene& s : scenes()) {
    INFO(s.name);
    const Bvh8Tree t = build_bvh8(s.soup);
    REQUIRE_NOTHROW(t.validate());
    CHECK(t.left_out == s.soup.degenerate_count());
    CHECK(t.prims.size() + t.left_out == s.soup.size());
    CHECK(t.depth >= 2);
  }
  const StiffScene degenerate = make_stiff_scene("degenerate");
  const Bvh8Tree d = build_bvh8(degenerate.soup);
  CHECK(d.left_out >= 16);
  CHECK_NOTHROW(d.validate());

  const Bvh8Tree good = build_bvh8(load_mesh(test::scene_path("suzanne.obj")));
  Bvh8Tree t = good;
  t.nodes[0].box[0][0] = std::nextafter(t.nodes[0].box[0][0], 1e30f);  // child box no longer holds its triangles
  CHECK_THROWS_AS(t.validate(), std::logic_error);
  t = good;
  t.nodes[0].child[0] = Bvh8Node::inner_ref(std::uint32_t(t.nodes.size()));  // out of range
  CHECK_THROWS_AS(t.validate(), std::logic_error);
  t = good;
  // The SoA rows' triangle number (what a float hit reports) no longer the list's:
  // row 9 of the leaf whose entries start at 0.
  std::uint32_t n0 = 0;
  for (const Bvh8Node& n : good.nodes)
    for (const std::uint32_t ref : n.child)
      if (ref != 0 && Bvh8Node::is_leaf(ref) && Bvh8Node::index(ref) == 0) n0 = Bvh8Node::count(ref);
  REQUIRE(n0 >= 1);
  float& number = t.leaf_soa[9 * n0];
  CHECK(Bvh8Tree::decode_prim(number) == t.prims[0]);
  CHECK(std::isnormal(number));  // never a subnormal in lanes the four-float loads compute on
  number = Bvh8Tree::encode_prim(t.prims[0] + 1);
  CHECK_THROWS_WITH(t.validate(), Catch::Contains("SoA triangle number and list differ"));
  for (const std::uint32_t p : {0u, 1u, 0x7fffffu, 0x800000u, 0xffffffu, 0x3fffffffu, 0xfffffffeu, 0xffffffffu})
    CHECK(Bvh8Tree::decode_prim(Bvh8Tree::encode_prim(p)) == p);
  t = good;
  t.prims[0] = t.prims[1];  // one triangle twice, another in no leaf
  CHECK_THROWS_AS(t.validate(), std::logic_error);
  CHECK_THROWS_AS(Bvh8Tracer(std::move(t)), UsageError);
  Bvh8Config bad;
  bad.min_leaf_size = 0;
  CHECK_THROWS_AS(build_bvh8(make_icosphere({0, 0, 0}, 1, 1), bad), UsageError);
  bad.min_leaf_size = 5;
  CHECK_THROWS_AS(build_bvh8(make_icosphere({0, 0, 0}, 1, 1), bad), UsageError);
  bad = Bvh8Config{};
  bad.sah_block_size = 0;
  CHECK_THROWS_AS(build_bvh8(make_icosphere({0, 0, 0}, 1, 1), bad), UsageError);
  bad = Bvh8Config{};
  bad.max_leaf_size = 0;
  bad.min_leaf_size = 0;
  CHECK_THROWS_AS(build_bvh8(make_icosphere({0, 0, 0}, 1, 1), bad), UsageError);
  bad.max_leaf_size = 16;
  CHECK_THROWS_AS(build_bvh8(make_icosphere({0, 0, 0}, 1, 1), bad), UsageError);
}

// Embree's own setting for four-triangle blocks: a node of at most
// min_leaf_size triangles is one four-lane test and is never split, not even
// to fill a node's eight slots (which rtcBuildBVH does with minLeafSize 1:
// sponza then had 31,791 leaves of one triangle among 45,239).
TEST_CASE("bvh8: nodes of at most min_leaf_size triangles are not split into smaller leaves", "[bvh8]") {
  const TriangleSoup soup = load_mesh(test::scene_path("suzanne.obj"));
  const auto per_leaf = [](const Bvh8Tree& t) {
    std::size_t leaves = 0, entries = 0;
    for (const Bvh8Node& n : t.nodes)
      for (const std::uint32_t ref : n.child)
        if (ref != 0 && Bvh8Node::is_leaf(ref)) ++leaves, entries += Bvh8Node::count(ref);
    CHECK(entries == t.prims.size());
    return double(entries) / double(leaves);
  };
  Bvh8Config one;
  one.min_leaf_size = 1;
  const Bvh8Tree a = build_bvh8(soup, one), b = build_bvh8(soup);
  INFO("triangles per leaf: " << per_leaf(a) << " with min_leaf_size 1, " << per_leaf(b) << " with 4");
  CHECK(per_leaf(a) < 2.5);
  CHECK(per_leaf(b) > 3.0);
  CHECK_NOTHROW(b.validate());
}

TEST_CASE("bvh8: exact leaves equal the exact reference, bit for bit", "[bvh8]") {
  for (const Scene& s : scenes()) {
    const ExactTracer exact(s.soup);
    const auto bvh = exact_bvh8(s.soup);
    const std::vector<Ray> rays = test_rays(s.soup, 1500);
    INFO(s.name << ": " << rays.size() << " rays");
    CHECK(differing(exact, *bvh, rays) == 0);
  }
}

TEST_CASE("bvh8: float leaves equal brute force on random rays", "[bvh8]") {
  for (const Scene& s : scenes()) {
    const BruteForceTracer brute(s.soup);
    const auto bvh = make_tracer("bvh8-float", s.soup);
    const std::vector<Ray> rays = random_rays(s.soup, 3000, 5);
    std::vector<Hit> a(rays.size()), b(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) a[i] = brute.trace(rays[i]), b[i] = bvh->trace(rays[i]);
    const HitComparison c = compare_hits(a, b);
    // The four-lane leaf test reproduces the scalar watertight test bit for bit.
    std::size_t same_prim_other_bits = 0;
    for (std::size_t i = 0; i < rays.size(); ++i)
      if (a[i].prim == b[i].prim && std::memcmp(&a[i], &b[i], sizeof(Hit)) != 0) ++same_prim_other_bits;
    INFO(s.name << ": lost " << c.lost << ", extra " << c.extra << ", farther " << c.farther);
    CHECK(c.agrees());
    CHECK(c.same_triangle + c.both_miss + c.tie == rays.size());
    CHECK(c.same_triangle > rays.size() / 10);
    CHECK(same_prim_other_bits == 0);
  }
}

TEST_CASE("bvh8: the plain x86-64, AVX2 and AVX-512 kernels agree bit for bit, hits and counters", "[bvh8]") {
  const TriangleSoup soup = load_mesh(test::scene_path("utah-teapot.obj"));
  Bvh8Tracer base(build_bvh8(soup)), wide(build_bvh8(soup));
  base.set_kernel_isa(Isa::Scalar);
  CHECK(base.kernel_isa() == Isa::Scalar);
  const std::vector<Ray> rays = test_rays(soup, 1000);
  std::vector<Hit> ref(rays.size());
  RayCounters cr;
  for (std::size_t i = 0; i < rays.size(); ++i) ref[i] = base.trace(rays[i], &cr);
  CHECK(cr.rays == rays.size());
  CHECK(cr.box_node_visits >= rays.size() / 2);  // invalid rays visit nothing
  for (const Isa isa : {Isa::Avx2, Isa::Avx512}) {
    if (int(detected_isa()) < int(isa)) {
      CHECK_THROWS_AS(wide.set_kernel_isa(isa), UsageError);
      continue;
    }
    wide.set_kernel_isa(isa);
    RayCounters cw;
    std::size_t bad = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Hit h = wide.trace(rays[i], &cw);
      bad += std::memcmp(&h, &ref[i], sizeof(Hit)) != 0 ? 1 : 0;
    }
    INFO(isa_name(isa));
    CHECK(bad == 0);
    CHECK(cw.box_node_visits == cr.box_node_visits);
    CHECK(cw.leaf_visits == cr.leaf_visits);
    CHECK(cw.triangle_tests == cr.triangle_tests);
  }
}

// trace_batch runs the kernel's own loop (no virtual call or ISA switch per
// ray); it must give what trace() gives ray by ray, counters included, with
// rays from beyond 2^126 (the fallback) mixed in, and in a scene beyond 2^126.
TEST_CASE("bvh8: trace_batch equals trace() ray by ray, hits and counters, on every kernel", "[bvh8]") {
  const auto same = [](const Accelerator& a, const std::vector<Ray>& rays) {
    std::vector<Hit> single(rays.size()), batch(rays.size());
    RayCounters cs, cb;
    for (std::size_t i = 0; i < rays.size(); ++i) single[i] = a.trace(rays[i], &cs);
    a.trace_batch(rays, batch, 1, &cb);
    std::size_t bad = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) bad += std::memcmp(&single[i], &batch[i], sizeof(Hit)) != 0 ? 1 : 0;
    CHECK(bad == 0);
    CHECK(cb.rays == rays.size());
    CHECK(cb.rays == cs.rays);
    CHECK(cb.box_node_visits == cs.box_node_visits);
    CHECK(cb.leaf_visits == cs.leaf_visits);
    CHECK(cb.triangle_tests == cs.triangle_tests);
    CHECK(cb.rule_decisions == cs.rule_decisions);
    CHECK(cb.exact_decisions == cs.exact_decisions);
    std::vector<Hit> uncounted(rays.size());
    a.trace_batch(rays, uncounted);
    CHECK(std::memcmp(uncounted.data(), batch.data(), rays.size() * sizeof(Hit)) == 0);
    std::size_t hits = 0;
    for (const Hit& h : batch) hits += h.hit() ? 1 : 0;
    return hits;
  };
  const TriangleSoup soup = load_mesh(test::scene_path("utah-teapot.obj"));
  std::vector<Ray> rays = test_rays(soup, 500);
  // Rays from beyond 2^126 towards the scene, between the others.
  Ray far;
  far.org = {0x1p127f, 0.5f, 0.5f};
  far.dir = {-1, 0, 0};
  rays.insert(rays.begin() + 7, far);
  far.org = {0.5f, -std::numeric_limits<float>::max(), 0.5f};
  far.dir = {0, 1, 0};
  rays.insert(rays.begin() + 300, far);
  const ExactTracer exact(soup);
  std::vector<Hit> ref(rays.size());
  exact.trace_batch(rays, ref);
  CHECK(ref[7].hit());
  CHECK(ref[300].hit());
  const CertifiedIntersector certified(soup);
  for (const bool exact_leaves : {true, false}) {
    for (const Isa isa : {Isa::Scalar, Isa::Avx2, Isa::Avx512}) {
      if (int(detected_isa()) < int(isa)) continue;
      INFO((exact_leaves ? "bvh8" : "bvh8-float") << " on the " << isa_name(isa) << " kernel");
      Bvh8Tracer t(build_bvh8(soup));
      if (exact_leaves) t.set_exact_leaf(&certified);
      t.set_kernel_isa(isa);
      CHECK(same(t, rays) > rays.size() / 4);
      std::vector<Hit> h(rays.size());
      t.trace_batch(rays, h);
      CHECK(h[7].hit());
      CHECK(h[300].hit());
      if (exact_leaves) {  // t and prim equal the exact reference's on every ray (u, v are computed differently)
        std::size_t bad = 0;
        for (std::size_t i = 0; i < rays.size(); ++i)
          bad += (h[i].prim != ref[i].prim || (h[i].hit() && h[i].t != ref[i].t)) ? 1 : 0;
        CHECK(bad == 0);
      }
    }
  }
  // Fewer hits than rays is a usage error, not a write past the end.
  Bvh8Tracer t(build_bvh8(soup));
  std::vector<Hit> short_hits(rays.size() - 1);
  CHECK_THROWS_AS(t.trace_batch(rays, short_hits), UsageError);
  // A scene beyond 2^126: the batch takes the fallback for every ray.
  const TriangleSoup huge = transformed_soup(make_icosphere({0, 0, 0}, 1.0f, 2), 0x1p100f, {0x1p126f, 0, 0});
  const auto hb = exact_bvh8(huge);
  CHECK(same(*hb, random_rays(huge, 300, 5)) > 50);
}

TEST_CASE("bvh8: counters, and counted hits equal uncounted ones", "[bvh8]") {
  const TriangleSoup soup = load_mesh(test::scene_path("suzanne.obj"));
  const auto bvh = exact_bvh8(soup);
  const std::vector<Ray> rays = vertex_rays(soup, 2000, 3);
  RayCounters c;
  std::size_t bad = 0;
  for (const Ray& r : rays) {
    const Hit x = bvh->trace(r), y = bvh->trace(r, &c);
    bad += std::memcmp(&x, &y, sizeof(Hit)) != 0 ? 1 : 0;
  }
  CHECK(bad == 0);
  CHECK(c.rays == rays.size());
  CHECK(c.box_node_visits >= rays.size());
  CHECK(c.leaf_visits >= rays.size() / 2);
  CHECK(c.triangle_tests >= c.leaf_visits);
  CHECK(c.rule_decisions > 0);  // rays through vertices: the exact leaf test's rules decide
}

namespace {
/// The certified intersector without its staged() promise: the traversals
/// then hand it every triangle their prefilter keeps, and it counts them itself.
class UnstagedIntersector final : public LeafIntersector {
 public:
  explicit UnstagedIntersector(const CertifiedIntersector& x) : x_(x) {}
  std::string name() const override { return "unstaged"; }
  void intersect(const Ray& ray, std::span<const std::uint32_t> prims, const LeafTriangle* corners,
                 NearestHit& best, RayCounters* counters) const override {
    x_.intersect(ray, prims, corners, best, counters);
  }

 private:
  const CertifiedIntersector& x_;
};
}  // namespace

// The kernel decides a leaf's triangles in three ways: the whole leaf from its
// lists, the prefilter's survivors gathered from the SoA rows, or (unstaged)
// the intersector alone. The answers and the counters must not depend on the
// way: the gathered path counts its tests and rule decisions itself.
TEST_CASE("bvh8: staged exact leaves count what the intersector counts, hits and counters", "[bvh8]") {
  for (const char* name : {"suzanne.obj", "utah-teapot.obj"}) {
    const TriangleSoup soup = load_mesh(test::scene_path(name));
    const CertifiedIntersector leaf(soup);
    const UnstagedIntersector unstaged(leaf);
    REQUIRE(leaf.staged());
    REQUIRE_FALSE(unstaged.staged());
    Bvh8Tracer staged_bvh(build_bvh8(soup)), unstaged_bvh(build_bvh8(soup));
    staged_bvh.set_exact_leaf(&leaf);
    unstaged_bvh.set_exact_leaf(&unstaged);
    std::vector<Ray> rays = vertex_rays(soup, 1500, 5);
    const std::vector<Ray> random = make_rays(RaySetKind::Random, soup, 1500, 6);
    rays.insert(rays.end(), random.begin(), random.end());
    RayCounters a, b;
    std::size_t bad = 0;
    for (const Ray& r : rays) {
      const Hit x = staged_bvh.trace(r, &a), y = unstaged_bvh.trace(r, &b);
      bad += std::memcmp(&x, &y, sizeof(Hit)) != 0 ? 1 : 0;
    }
    INFO(name << ": " << rays.size() << " rays");
    CHECK(bad == 0);
    CHECK(a.leaf_visits == b.leaf_visits);
    CHECK(a.triangle_tests == b.triangle_tests);
    CHECK(a.rule_decisions == b.rule_decisions);
    CHECK(a.exact_decisions == b.exact_decisions);
    CHECK(a.rule_decisions > 0);  // vertex rays: the rules decide, in every path
  }
}

// The boxes are the triangles' exact float bounds, and the box test keeps every
// point of the exact ray; moving each face in by one float step drops the
// corners on the faces, where rays through vertices hit.
TEST_CASE("bvh8: boxes shrunk by one float step lose hits on vertex rays", "[bvh8]") {
  const TriangleSoup soup = load_mesh(test::scene_path("utah-teapot.obj"));
  const ExactTracer exact(soup);
  const CertifiedIntersector leaf(soup);
  Bvh8Tracer tight(build_bvh8(soup)), shrunk(build_bvh8(soup));
  tight.set_exact_leaf(&leaf);
  shrunk.set_exact_leaf(&leaf);
  shrunk.shrink_boxes_for_testing();
  const std::vector<Ray> rays = vertex_rays(soup, 3000, 9);
  const std::size_t bad_tight = differing(exact, tight, rays), bad_shrunk = differing(exact, shrunk, rays);
  INFO("differing hits: tight " << bad_tight << ", shrunk " << bad_shrunk << " of " << rays.size());
  CHECK(bad_tight == 0);
  CHECK(bad_shrunk > 0);
}

// Beyond 2^126, p - o could overflow in float; such rays and scenes are traced
// against every triangle, still exactly.
TEST_CASE("bvh8: coordinates beyond 2^126 are traced exactly", "[bvh8]") {
  const TriangleSoup far = transformed_soup(make_icosphere({0, 0, 0}, 1.0f, 2), 0x1p100f, {0x1p126f, 0, 0});
  const ExactTracer exact(far);
  const auto bvh = exact_bvh8(far);
  std::vector<Ray> rays = random_rays(far, 500, 2);
  const std::vector<Ray> v = vertex_rays(far, 500, 3);
  rays.insert(rays.end(), v.begin(), v.end());
  CHECK(differing(exact, *bvh, rays) == 0);
  std::size_t hits = 0;
  for (const Ray& r : rays) hits += bvh->trace(r).hit() ? 1 : 0;
  CHECK(hits > rays.size() / 4);
  // A scene near the origin and a ray from beyond 2^126 towards it.
  const TriangleSoup near = make_icosphere({0, 0, 0}, 1.0f, 2);
  const auto b = exact_bvh8(near);
  const ExactTracer e(near);
  Ray r;
  r.org = {0x1p127f, 0.25f, 0.25f};
  r.dir = {-1, 0, 0};
  CHECK(b->trace(r).hit());
  CHECK(b->trace(r).prim == e.trace(r).prim);
}

// Any-hit queries stop at the first hit a leaf proves: the same answer as the
// nearest hit, with less work on rays that hit.
TEST_CASE("bvh8: occluded equals trace().hit() and stops early", "[bvh8]") {
  const TriangleSoup soup = load_mesh(test::scene_path("utah-teapot.obj"));
  const std::vector<Ray> rays = test_rays(soup, 1000);
  for (const char* mode : {"bvh8", "bvh8-float"}) {
    const auto t = make_tracer(mode, soup);
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
    CHECK(any.triangle_tests < nearest.triangle_tests);
  }
}

namespace {

TriangleSoup one_triangle(Vec3f a, Vec3f b, Vec3f c) {
  TriangleSoup s;
  s.vertices = {a, b, c};
  s.triangles = {{0, 1, 2}};
  classify_degenerate(s);
  return s;
}

/// bvh8 (exact leaves) and the exact reference agree on `ray`, which hits.
void check_exact_hit(const TriangleSoup& s, const Ray& ray) {
  const ExactTracer exact(s);
  const auto bvh = exact_bvh8(s);
  const Hit e = exact.trace(ray), h = bvh->trace(ray);
  REQUIRE(e.hit());
  CHECK(h.prim == e.prim);
  CHECK(h.t == e.t);
  CHECK(bvh->occluded(ray));
}

}  // namespace

// The prefilter's bound is computed without subnormal operands (exact_prefilter.h); it must
// equal the documented formula max(2^-18 Mx My, 2^-145 (Mx + My), 2^-120), evaluated in
// plain float operations, bit for bit (NaN as NaN) on random magnitudes and the edges.
TEST_CASE("exact prefilter: the bound equals its formula", "[bvh8][prefilter]") {
  const auto formula = [](float mx, float my) {
    const auto mx_ = [](float a, float b) { return a > b ? a : b; };  // simd::max's order
    volatile float tiny = 0x1p-145f;  // volatile: evaluated at run time, subnormal and all
    return mx_(mx_(0x1p-18f * (mx * my), tiny * (mx + my)), 0x1p-120f);
  };
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> v = {0.0f, 0x1p-149f, 0x1p-126f, 1e-30f, 1e-3f, 1.0f, 0x1p24f, 0x1.fffffep24f, 0x1p25f,
                          0x1.000002p25f, 3e7f, 1e20f, std::numeric_limits<float>::max(), inf, nan};
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> e(-140.0f, 126.0f);
  for (int i = 0; i < 2000; ++i) v.push_back(std::exp2(e(rng)));
  std::size_t checked = 0;
  for (std::size_t i = 0; i < v.size(); i += 4) {
    for (std::size_t j = 0; j < v.size(); j += 97) {
      float a[4], b[4];
      for (int k = 0; k < 4; ++k) a[k] = v[(i + k) % v.size()], b[k] = v[(j + 13 * k) % v.size()];
      const auto got = detail::exact_filter_bound(simd::load<4>(a), simd::load<4>(b));
      for (int k = 0; k < 4; ++k) {
        const float want = formula(a[k], b[k]);
        INFO("mx " << a[k] << " my " << b[k]);
        if (std::isnan(want))
          CHECK(std::isnan(got[k]));
        else
          CHECK(std::bit_cast<std::uint32_t>(got[k]) == std::bit_cast<std::uint32_t>(want));
        ++checked;
      }
    }
  }
  CHECK(checked > 10000);
}

// Found reviewing the exact leaves' float filter (issue #26): with a direction
// component of 2^-149 the shear sx rounds to a subnormal with far more than
// 2^-24 relative error, and the filter's bound called a hit a certain miss.
// A ray with a nonzero subnormal shear now keeps every lane.
TEST_CASE("bvh8: a subnormal shear does not let the float filter drop a hit", "[bvh8][regression]") {
  const float z = 0x1p120f;
  Ray r;
  r.org = {0, 0, 0};
  r.dir = {0x1p-149f, 0, 1.5f};
  check_exact_hit(one_triangle({0x1p-30f, -1, z}, {0x1p-30f, 1, z}, {0x1.ap-30f, 0, z}), r);
  // sx = 2^-140 exactly, but subnormal: its products with a[kz] underflow too.
  const float w = 1.0f + 9 * 0x1p-13f;
  r.dir = {0x1p-140f, 0, 1};
  check_exact_hit(one_triangle({-600 * 0x1p-149f, 0, 1}, {513 * 0x1p-149f, 0x1p40f, w}, {512 * 0x1p-149f, -0x1p41f, w}),
                  r);
}

// The same review: with a normal shear (2^-126) the products sx a[kz] can still
// underflow, each 2^-150 off, which the weights scale by My; the bound gained
// 2^-145 (Mx + My). The sheared corners equal the second ray's above.
TEST_CASE("bvh8: an underflowing shear product does not let the float filter drop a hit", "[bvh8][regression]") {
  const float w = (1.0f + 9 * 0x1p-13f) * 0x1p-14f;
  Ray r;
  r.org = {0, 0, 0};
  r.dir = {0x1p-126f, 0, 1};
  check_exact_hit(one_triangle({-600 * 0x1p-149f, 0, 0x1p-14f}, {513 * 0x1p-149f, 0x1p40f, w},
                               {512 * 0x1p-149f, -0x1p41f, w}),
                  r);
}
