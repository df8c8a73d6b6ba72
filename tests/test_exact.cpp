// The exact reference tracer and the certified (filtered exact) triangle test:
// hand-built cases with known answers, then ray by ray equality of the two on
// shared meshes and stiff rays (vertex- and edge-aimed), where float tests
// disagree with the exact answer.
#include <catch2/catch.hpp>

#include "geometry/scenes/default_scene.h"
#include "geometry/io/load_mesh.h"
#include "geometry/scenes/ray_gen.h"
#include "robust/certified_intersector.h"
#include "robust/degenerate.h"
#include "robust/exact_tracer.h"
#include "test_util.h"

using namespace bsprt;

namespace {

/// A closed fan: `n` triangles around the apex (0,0,1) over a regular n-gon
/// in z = 0, plus the base fan around the origin: a closed double pyramid.
TriangleSoup double_pyramid(int n) {
  TriangleSoup s;
  s.vertices.push_back({0, 0, 1});
  s.vertices.push_back({0, 0, -1});
  for (int i = 0; i < n; ++i) {
    const float a = 6.2831853f * float(i) / float(n);
    s.vertices.push_back({std::cos(a), std::sin(a), 0});
  }
  for (int i = 0; i < n; ++i) {
    const std::uint32_t p = 2 + std::uint32_t(i), q = 2 + std::uint32_t((i + 1) % n);
    s.triangles.push_back({0, p, q});
    s.triangles.push_back({1, q, p});
  }
  classify_degenerate(s);
  return s;
}

void require_same(const Hit& exact, const Hit& tested, std::size_t i) {
  INFO("ray " << i << ": exact prim " << exact.prim << " t " << exact.t << ", tested prim " << tested.prim << " t "
              << tested.t);
  REQUIRE(exact.prim == tested.prim);
  REQUIRE(exact.t == tested.t);  // both are the exact t rounded to nearest
  if (exact.hit()) {
    CHECK(exact.u == Approx(tested.u).margin(1e-6));
    CHECK(exact.v == Approx(tested.v).margin(1e-6));
  }
}

}  // namespace

TEST_CASE("exact tracer: hand-built answers", "[exact]") {
  TriangleSoup s;
  s.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  s.triangles = {{0, 1, 2}};
  classify_degenerate(s);
  const ExactTracer exact(s);
  const CertifiedBruteTracer certified(s);
  Ray r;
  r.org = {0.25f, 0.25f, -2.0f};
  r.dir = {0, 0, 0.5f};
  for (const Accelerator* t : {static_cast<const Accelerator*>(&exact), static_cast<const Accelerator*>(&certified)}) {
    const Hit h = t->trace(r);
    CHECK(h.prim == 0);
    CHECK(h.t == 4.0f);
    CHECK(h.u == 0.25f);
    CHECK(h.v == 0.25f);
    Ray short_ray = r;
    short_ray.tfar = 3.999f;
    CHECK_FALSE(t->trace(short_ray).hit());
    Ray in_plane = r;  // lying in the triangle's plane: not a hit (watertight convention)
    in_plane.org = {-1, 0.25f, 0};
    in_plane.dir = {1, 0, 0};
    CHECK_FALSE(t->trace(in_plane).hit());
    Ray bad = r;
    bad.dir = {0, 0, 0};
    CHECK_FALSE(t->trace(bad).hit());
  }
}

TEST_CASE("exact and certified agree through a closed fan's shared vertex and edges", "[exact]") {
  const TriangleSoup s = double_pyramid(7);
  const ExactTracer exact(s);
  const CertifiedBruteTracer certified(s);
  // Rays exactly through the apex, through points of shared edges, from
  // outside and from inside: all hit, at the right t, equal triangle.
  std::vector<Ray> rays;
  for (int i = 0; i < 50; ++i) {
    Ray r;
    r.org = {0.37f * float(i % 7) - 1.1f, 0.21f * float(i % 5) - 0.4f, 3.0f};
    r.dir = Vec3f{0, 0, 1} - r.org;  // the apex, at t = 1 up to the rounding of dir
    rays.push_back(r);
    Ray in;
    in.org = {0, 0, 0.01f * float(i) - 0.25f};  // inside, on the axis
    in.dir = {std::cos(0.3f * float(i)), std::sin(0.3f * float(i)), 0.2f * float(i % 3) - 0.2f};
    rays.push_back(in);
  }
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Hit e = exact.trace(rays[i]);
    require_same(e, certified.trace(rays[i]), i);
    if (i % 2 == 1) CHECK(e.hit());  // from inside a closed mesh: never escapes
  }
}

TEST_CASE("certified test equals the exact reference on stiff rays", "[exact]") {
  for (const char* mesh : {"cube.obj", "suzanne.obj", "stiff_cube_with_fold.ply", "stiff_degenerated.obj"}) {
    const TriangleSoup s = load_mesh(bsprt::test::scene_path(mesh));
    const ExactTracer exact(s);
    const CertifiedBruteTracer certified(s);
    for (RaySetKind kind : {RaySetKind::Random, RaySetKind::Vertex, RaySetKind::Edge}) {
      const auto rays = make_rays(kind, s, 1500, 11);
      std::size_t hits = 0;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        INFO(mesh << " " << ray_set_name(kind));
        const Hit e = exact.trace(rays[i]);
        require_same(e, certified.trace(rays[i]), i);
        hits += e.hit();
      }
      CHECK(hits > 0);
    }
  }
}

TEST_CASE("rays from inside a closed sphere always hit (certified)", "[exact]") {
  const TriangleSoup s = make_icosphere({1e5f, -3e4f, 2e5f}, 0.5f, 3);  // far from the origin
  const CertifiedBruteTracer certified(s);
  const ExactTracer exact(s);
  std::size_t escaped = 0;
  const auto dirs = random_rays(s, 2000, 3);
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    Ray r;
    r.org = {1e5f, -3e4f, 2e5f};
    r.dir = dirs[i].dir;
    const Hit h = certified.trace(r);
    escaped += !h.hit();
    if (i < 300) require_same(exact.trace(r), h, i);
  }
  CHECK(escaped == 0);
}

// Regression (found by profiling bsp-certified, 2026-11-22): a triangle is
// listed in every leaf it touches, so a ray meets its nearest triangle again in
// later leaves; the equal enclosures sent each repeat to the exact rational
// comparison, which made bsp-certified 3-4x slower than bsp on bunny rays.
TEST_CASE("regression: certified leaf test meeting its nearest triangle again decides without exact arithmetic",
          "[exact][regression]") {
  TriangleSoup s;
  s.vertices = {{0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {0, 0, 2}, {1, 0, 2}, {0, 1, 2}};
  s.triangles = {{0, 1, 2}, {3, 4, 5}};
  classify_degenerate(s);
  const CertifiedIntersector cert(s);
  Ray r;
  r.org = {0.25f, 0.25f, 0.0f};
  r.dir = {0.0f, 0.0f, 1.0f};
  NearestHit best;
  RayCounters c;
  const std::uint32_t near_leaf[] = {0}, far_leaf[] = {0, 1};  // triangle 0 listed in both leaves
  cert.intersect(r, near_leaf, best, &c);
  REQUIRE(best.hit.prim == 0);
  const Hit first = best.hit;
  cert.intersect(r, far_leaf, best, &c);
  CHECK(best.hit.prim == first.prim);
  CHECK(best.hit.t == first.t);
  CHECK(best.hit.t == 1.0f);
  CHECK(c.triangle_tests == 3);        // every listed pair is counted
  CHECK(cert.exact_fallbacks() == 0);  // no rational arithmetic for the repeat
  // A different triangle at the same t still gets the exact tie-break.
  TriangleSoup twin = s;
  twin.triangles = {{0, 1, 2}, {0, 1, 2}};
  classify_degenerate(twin);
  const CertifiedIntersector cert2(twin);
  NearestHit b2;
  const std::uint32_t both[] = {1, 0};
  cert2.intersect(r, both, b2, nullptr);
  CHECK(b2.hit.prim == 0);  // exact tie: the lower triangle number
  CHECK(cert2.exact_fallbacks() == 0);  // same corners: the same exact t by rule (issue #23)
}
