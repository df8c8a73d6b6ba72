// Brute force (watertight test) against Embree 3 in robust mode on the shared
// meshes: random rays must agree on hit/miss and on the nearest t; a different
// triangle is fine only at the same t (a tie at a shared edge or vertex).
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "bsprt/error.h"
#include "geometry/io/load_mesh.h"
#include "bsprt/ray.h"
#include "geometry/core/triangle_soup.h"
#include "test_util.h"
#include "traverse/brute_force.h"
#include "traverse/simd/cpu_features.h"
#include "traverse/embree/embree_tracer.h"
#include "traverse/simd/watertight_packet_brute.h"

using namespace bsprt;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

Box3f bounds_of(const TriangleSoup& s) {
  Box3f b;
  for (const Vec3f& v : s.vertices) b.extend(v);
  return b;
}

Vec3f rand_dir(std::mt19937& g) {
  std::uniform_real_distribution<float> u(-1, 1);
  for (;;) {
    const Vec3f d{u(g), u(g), u(g)};
    if (dot(d, d) > 1e-4f && dot(d, d) <= 1.0f) return d;
  }
}

/// Half the rays in random directions, half aimed at random points inside
/// random triangles; origins in the bounding box grown by half its size.
std::vector<Ray> random_rays(const TriangleSoup& s, std::size_t n, unsigned seed) {
  std::mt19937 g(seed);
  const Box3f b = bounds_of(s);
  const Vec3f lo = b.lo - b.diagonal() * 0.5f, hi = b.hi + b.diagonal() * 0.5f;
  std::uniform_real_distribution<float> u01(0, 1);
  std::vector<Ray> rays(n);
  for (std::size_t i = 0; i < n; ++i) {
    Ray& r = rays[i];
    r.org = {lo.x + u01(g) * (hi.x - lo.x), lo.y + u01(g) * (hi.y - lo.y), lo.z + u01(g) * (hi.z - lo.z)};
    if (i % 2 == 0) {
      r.dir = rand_dir(g);
    } else {
      const auto c = s.corners(std::uint32_t(g() % s.size()));
      float wu = u01(g), wv = u01(g);
      if (wu + wv > 1) wu = 1 - wu, wv = 1 - wv;
      r.dir = c[0] * (1 - wu - wv) + c[1] * wu + c[2] * wv - r.org;
    }
  }
  return rays;
}

/// Brute-force hits, in the widest native packets (equal to single rays).
std::vector<Hit> brute_hits(const TriangleSoup& s, const std::vector<Ray>& rays) {
  std::vector<Hit> hits(rays.size());
  brute_force_trace_batch(s, rays, hits, isa_width(detected_isa()), nullptr);
  return hits;
}

/// Ray-by-ray comparison; returns the number of disagreements.
std::size_t compare(const std::vector<Hit>& ref, const std::vector<Hit>& got, const std::string& what,
                    bool check_uv) {
  std::size_t bad = 0, both = 0, ties = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    const Hit &a = ref[i], &b = got[i];
    if (!a.hit() && !b.hit()) continue;
    bool ok = a.hit() && b.hit() && std::abs(a.t - b.t) <= 1e-4f * std::max(std::abs(a.t), 1e-3f);
    if (ok && a.prim == b.prim && check_uv) ok = std::abs(a.u - b.u) < 1e-3f && std::abs(a.v - b.v) < 1e-3f;
    both += a.hit() && b.hit();
    ties += ok && a.prim != b.prim;
    if (!ok && bad++ < 5)
      WARN(what << " ray " << i << ": brute t=" << a.t << " prim=" << a.prim << " u=" << a.u << " v=" << a.v
                << " | other t=" << b.t << " prim=" << b.prim << " u=" << b.u << " v=" << b.v);
  }
  INFO(what << ": " << both << " both hit, " << ties << " ties on other triangles, " << bad << " disagree");
  CHECK(both > ref.size() / 4);
  return bad;
}

void run_mesh(const std::string& name, std::size_t n_rays) {
  const TriangleSoup soup = load_mesh(test::scene_path(name));
  REQUIRE(soup.size() > 0);
  const std::vector<Ray> rays = random_rays(soup, n_rays, 1234);
  const std::vector<Hit> ref = brute_hits(soup, rays);
  const EmbreeTracer embree(soup);
  CHECK(embree.name() == "embree");
  std::vector<Hit> got(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) got[i] = embree.trace(rays[i]);
  CHECK(compare(ref, got, name + " embree", true) == 0);
  for (int w : {4, 8, 16}) {
    embree.trace_batch(rays, got, w);
    CHECK(compare(ref, got, name + " embree packets of " + std::to_string(w), true) == 0);
  }
}

}  // namespace

TEST_CASE("brute vs embree: cube", "[brute][embree]") { run_mesh("cube.obj", 5000); }
TEST_CASE("brute vs embree: suzanne", "[brute][embree]") { run_mesh("suzanne.obj", 5000); }
TEST_CASE("brute vs embree: utah teapot", "[brute][embree]") { run_mesh("utah-teapot.obj", 5000); }
TEST_CASE("brute vs embree: stanford bunny", "[brute][embree]") { run_mesh("stanford-bunny.obj", 2000); }

TEST_CASE("embree: degenerate triangles, numbering, invalid rays, modes", "[embree]") {
  TriangleSoup s;
  s.vertices = {{0, 0, 5}, {1, 1, 5}, {2, 2, 5}, {-1, -1, 6}, {3, -1, 6}, {-1, 3, 6}};
  s.triangles = {{0, 1, 2}, {3, 4, 5}, {1, 1, 1}};
  s.degenerate = {1, 0, 1};
  for (const bool robust : {true, false}) {
    const EmbreeTracer e(s, EmbreeConfig{robust, robust});
    CHECK(e.name() == (robust ? "embree" : "embree-fast"));
    CHECK(e.memory_bytes() > 0);
    Ray r;
    r.org = {0, 0, 0}, r.dir = {0, 0, 1};
    Hit h = e.trace(r);
    CHECK(h.prim == 1);  // the degenerate triangle in front is not hit; numbering kept
    CHECK(h.t == Approx(6.0f));
    CHECK(h.u == Approx(0.25f));
    CHECK(h.v == Approx(0.25f));
    std::vector<Ray> rays(21, r);
    rays[3].dir = {0, 0, 0};
    rays[5].org.x = std::numeric_limits<float>::quiet_NaN();
    rays[7].tnear = 10.0f, rays[7].tfar = 1.0f;
    rays[9].dir.y = kInf;
    std::vector<Hit> hits(rays.size());
    for (int w : {1, 4, 8, 16}) {
      RayCounters c;
      e.trace_batch(rays, hits, w, &c);
      CHECK(c.rays == rays.size());
      for (std::size_t i = 0; i < rays.size(); ++i) {
        const bool bad = i == 3 || i == 5 || i == 7 || i == 9;
        CHECK(hits[i].hit() == !bad);
        if (bad) CHECK(hits[i].t == kInf);
        else CHECK(hits[i].prim == 1);
      }
    }
  }
  const TriangleSoup empty;
  const EmbreeTracer e(empty);
  Ray r;
  r.dir = {1, 0, 0};
  CHECK_FALSE(e.trace(r).hit());
}

// Regression: a valid ray with tnear < 0 (or a component above Embree's
// FLT_LARGE) aborted the process in Embree's assertion "ray.tnear() >= 0.0f"
// (found tracing the stiff special rays with --accel embree).
TEST_CASE("embree: a valid ray Embree cannot trace is a usage error naming it and not a crash", "[embree][regression]") {
  TriangleSoup s;
  s.vertices = {{-1, -1, 6}, {3, -1, 6}, {-1, 3, 6}};
  s.triangles = {{0, 1, 2}};
  s.degenerate = {0};
  const EmbreeTracer e(s);
  Ray ok;
  ok.org = {0, 0, 0}, ok.dir = {0, 0, 1};
  const auto bad_rays = [&] {
    std::vector<Ray> bad(3, ok);
    bad[0].tnear = -1.0f;
    bad[1].org.x = 1e19f;
    bad[2].dir.y = -1e19f;
    return bad;
  }();
  for (const Ray& bad : bad_rays) {
    CHECK_THROWS_AS(e.trace(bad), UsageError);
    for (int w : {1, 4, 8, 16}) {
      std::vector<Ray> rays(20, ok);
      rays[13] = bad;
      std::vector<Hit> hits(rays.size());
      try {
        e.trace_batch(rays, hits, w);
        FAIL("no error for width " << w);
      } catch (const UsageError& err) {
        CHECK(std::string(err.what()).find("ray 13 ") != std::string::npos);
      }
      for (const Hit& h : hits) CHECK_FALSE(h.hit());  // refused before tracing
    }
  }
  // At the limit, and invalid rays with a negative tnear (tnear > tfar), are traced as before.
  Ray edge = ok;
  edge.dir = {0, 0, 1e18f};
  CHECK(e.trace(edge).hit());
  CHECK(e.trace(edge).t == Approx(6e-18f));
  Ray invalid = ok;
  invalid.tnear = -1.0f, invalid.tfar = -2.0f;
  CHECK_FALSE(e.trace(invalid).hit());
}
