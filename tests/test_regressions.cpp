// Named regression tests: every fuzzer finding (fuzz/) and every stiff-case
// failure becomes one test here, with the input written out in code.
#include <catch2/catch.hpp>

#include "geometry/error.h"
#include "stiff_util.h"

using namespace bsprt;
using namespace bsprt::test;

/// Adds triangle (a, b, c) with its own vertices.
static void add_tri(TriangleSoup& s, Vec3f a, Vec3f b, Vec3f c) {
  const auto n = std::uint32_t(s.vertices.size());
  s.vertices.insert(s.vertices.end(), {a, b, c});
  s.triangles.push_back({n, n + 1, n + 2});
  s.degenerate.push_back(0);
}

static Ray ray_of(Vec3f org, Vec3f dir) {
  Ray r;
  r.org = org, r.dir = dir;
  return r;
}

// Found by tests/test_stiff.cpp (stacks, axis-plane rays): the exact reference
// counted a ray lying in a triangle's plane and touching only its corner
// (CGAL's intersection is then a single point) as a hit, while every bsprt
// tracer (and its own documentation) treats rays in the plane as misses.
TEST_CASE("exact reference: a ray in a triangle's plane touching a corner misses", "[regression]") {
  TriangleSoup s;
  add_tri(s, {0.5f, 0.25f, 1}, {2.5f, 0.25f, 1}, {0.5f, 2.25f, 1});
  const Ray corner = ray_of({1.21042895f, 3.63322997f, 1}, {-0.710428953f, -1.38322997f, 0});
  const Ray edge = ray_of({-1, 0.25f, 1}, {1, 0, 0});  // along the edge y = 0.25
  for (const char* accel : {"exact", "brute-certified", "brute"}) {
    INFO(accel);
    const auto t = make_tracer(accel, s);
    CHECK_FALSE(t->trace(corner).hit());
    CHECK_FALSE(t->trace(edge).hit());
  }
  // The same corner reached by a slanted ray is a hit.
  const Ray slanted = ray_of({1.21042895f, 3.63322997f, 2}, {-0.710428953f, -1.38322997f, -1});
  CHECK(make_tracer("exact", s)->trace(slanted).hit());
}

#include <cstdio>
#include "geometry/stiff_rays.h"
#include "geometry/stiff_scenes.h"
TEST_CASE("debug", "[.debug]") {
  const StiffScene sc = make_stiff_scene("stacks");
  const auto rays = stiff_rays(StiffRayKind::AxisPlane, sc.soup, 300, 1005);
  auto ex = make_tracer("exact", sc.soup);
  auto bc = make_tracer("brute-certified", sc.soup);
  auto br = make_tracer("brute", sc.soup);
  int shown = 0;
  for (std::size_t i = 0; i < rays.size() && shown < 4; ++i) {
    const Ray& r = rays[i];
    Hit a = ex->trace(r), b = bc->trace(r), c = br->trace(r);
    if (a.prim == b.prim && (a.t == b.t)) continue;
    ++shown;
    std::printf("ray %zu org %.9g %.9g %.9g dir %.9g %.9g %.9g\n exact %u t=%.9g u=%g v=%g\n cert %u t=%.9g\n brute %u t=%.9g\n", i,
      r.org.x, r.org.y, r.org.z, r.dir.x, r.dir.y, r.dir.z, a.prim, a.t, a.u, a.v, b.prim, b.t, c.prim, c.t);
    for (std::uint32_t p : {a.prim, b.prim}) if (p != kNoHit) { auto cs = sc.soup.corners(p);
      std::printf("  tri %u: (%.9g %.9g %.9g) (%.9g %.9g %.9g) (%.9g %.9g %.9g)\n", p, cs[0].x, cs[0].y, cs[0].z, cs[1].x, cs[1].y, cs[1].z, cs[2].x, cs[2].y, cs[2].z); }
  }
}
