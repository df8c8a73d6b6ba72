// The watertight ray/triangle test (traverse/watertight.h), the brute-force
// oracle and its packet kernels (traverse/watertight_packet*.h): hand-built
// cases with exact answers, rays through shared edges and vertices of closed
// fans and solids, invalid rays, and packets equal to single rays bit for bit.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "bsprt/error.h"
#include "bsprt/ray.h"
#include "geometry/core/triangle_soup.h"
#include "traverse/brute_force.h"
#include "traverse/simd/cpu_features.h"
#include "traverse/watertight.h"
#include "traverse/simd/watertight_packet.h"
#include "traverse/simd/watertight_packet_brute.h"

using namespace bsprt;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

Ray make_ray(Vec3f org, Vec3f dir, float tnear = 0.0f, float tfar = kInf) {
  Ray r;
  r.org = org, r.dir = dir, r.tnear = tnear, r.tfar = tfar;
  return r;
}

std::optional<TriangleHit> hit_one(const Ray& r, Vec3f a, Vec3f b, Vec3f c) {
  return intersect_watertight(watertight_precompute(r), a, b, c);
}

/// Adds triangle (a, b, c) with its own three vertices.
void add_tri(TriangleSoup& s, Vec3f a, Vec3f b, Vec3f c) {
  const auto n = std::uint32_t(s.vertices.size());
  s.vertices.insert(s.vertices.end(), {a, b, c});
  s.triangles.push_back({n, n + 1, n + 2});
  s.degenerate.push_back(0);
}

/// Mean normal of the fan below.
constexpr Vec3f kFanNormal{-1, 1, 1};

/// A closed, non-planar fan of 8 triangles around `c` (integer coordinates, so
/// points on its edges are exact); every other ring vertex is lifted along the
/// normal e1 x e2 = kFanNormal.
TriangleSoup make_fan(Vec3f c) {
  const Vec3f e1{1, 0, 1}, e2{0, 1, -1}, n = kFanNormal;
  const int ab[8][2] = {{2, 0}, {2, 2}, {0, 2}, {-2, 2}, {-2, 0}, {-2, -2}, {0, -2}, {2, -2}};
  TriangleSoup s;
  s.vertices.push_back(c);
  for (int k = 0; k < 8; ++k)
    s.vertices.push_back(c + e1 * float(ab[k][0]) + e2 * float(ab[k][1]) + n * float(k % 2));
  for (std::uint32_t k = 0; k < 8; ++k) s.triangles.push_back({0, 1 + k, 1 + (k + 1) % 8});
  s.degenerate.assign(8, 0);
  return s;
}

/// A closed tetrahedron (0,0,0), (4,0,0), (0,4,0), (0,0,4), shared vertices.
TriangleSoup make_tetra() {
  TriangleSoup s;
  s.vertices = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {0, 0, 4}};
  s.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  s.degenerate.assign(4, 0);
  return s;
}

/// A closed cube [-1, 1]^3 of 12 triangles, shared vertices.
TriangleSoup make_cube() {
  TriangleSoup s;
  for (int i = 0; i < 8; ++i) s.vertices.push_back({i & 1 ? 1.f : -1.f, i & 2 ? 1.f : -1.f, i & 4 ? 1.f : -1.f});
  const std::uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : q) {
    s.triangles.push_back({f[0], f[1], f[2]});
    s.triangles.push_back({f[0], f[2], f[3]});
  }
  s.degenerate.assign(12, 0);
  return s;
}

bool same_bits(const Hit& a, const Hit& b) { return std::memcmp(&a, &b, sizeof(Hit)) == 0; }

/// Packet widths this CPU can run natively.
std::vector<int> native_widths() {
  std::vector<int> w;
  for (int width : {4, 8, 16})
    if (int(detected_isa()) >= int(isa_for_width(width))) w.push_back(width);
  return w;
}

/// Every native packet width gives the scalar brute-force hits bit for bit.
void check_packets_match(const TriangleSoup& soup, const std::vector<Ray>& rays) {
  const BruteForceTracer brute(soup);
  std::vector<Hit> expect(rays.size());
  RayCounters c1;
  for (std::size_t i = 0; i < rays.size(); ++i) expect[i] = brute.trace(rays[i], &c1);
  for (int width : native_widths()) {
    INFO("packet width " << width << ", isa " << isa_name(detected_isa()));
    std::vector<Hit> got(rays.size());
    RayCounters c2;
    brute_force_trace_batch(soup, rays, got, width, &c2);
    std::size_t mismatches = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) mismatches += same_bits(expect[i], got[i]) ? 0 : 1;
    CHECK(mismatches == 0);
    CHECK(c2.rays == c1.rays);
    CHECK(c2.triangle_tests == c1.triangle_tests);
  }
}

float rand_in(std::mt19937& g, float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(g); }

Vec3f rand_dir(std::mt19937& g) {
  for (;;) {
    const Vec3f d{rand_in(g, -1, 1), rand_in(g, -1, 1), rand_in(g, -1, 1)};
    const float l = dot(d, d);
    if (l > 1e-4f && l <= 1.0f) return d;
  }
}

/// n random triangles of about `size` around points of [-1, 1]^3.
TriangleSoup random_soup(std::mt19937& g, int n, float size) {
  TriangleSoup soup;
  for (int i = 0; i < n; ++i) {
    const Vec3f c{rand_in(g, -1, 1), rand_in(g, -1, 1), rand_in(g, -1, 1)};
    add_tri(soup, c + rand_dir(g) * size, c + rand_dir(g) * size, c + rand_dir(g) * size);
  }
  return soup;
}

/// Rays of `rays` that hit `soup` (brute force).
std::size_t brute_hits(const TriangleSoup& soup, const std::vector<Ray>& rays) {
  const BruteForceTracer brute(soup);
  std::size_t hits = 0;
  for (const Ray& r : rays) hits += brute.trace(r).hit() ? 1 : 0;
  return hits;
}

}  // namespace

TEST_CASE("watertight: ray through the middle gives exact t, u, v", "[watertight]") {
  const Vec3f a{-1, -1, 5}, b{3, -1, 5}, c{-1, 3, 5};
  auto h = hit_one(make_ray({0, 0, 0}, {0, 0, 1}), a, b, c);
  REQUIRE(h);
  CHECK(h->t == 5.0f);
  CHECK(h->u == 0.25f);
  CHECK(h->v == 0.25f);
  // Scaled and reversed directions (kz with dir < 0 swaps kx, ky).
  h = hit_one(make_ray({0, 0, 0}, {0, 0, 2}), a, b, c);
  REQUIRE(h);
  CHECK(h->t == 2.5f);
  h = hit_one(make_ray({0, 0, 10}, {0, 0, -2}), a, b, c);
  REQUIRE(h);
  CHECK(h->t == 2.5f);
  CHECK(h->u == 0.25f);
  CHECK(h->v == 0.25f);
  // Back side hits too (no culling), and other dominant axes.
  h = hit_one(make_ray({0, 0, 0}, {0, 0, 1}), a, c, b);
  REQUIRE(h);
  CHECK(h->u == 0.25f);
  CHECK(h->v == 0.25f);
  h = hit_one(make_ray({0, 0, 0}, {-4, 0, 0}), {-8, -1, -1}, {-8, 3, -1}, {-8, -1, 3});
  REQUIRE(h);
  CHECK(h->t == 2.0f);
  CHECK(h->u == 0.25f);
  CHECK(h->v == 0.25f);
  // u is the weight of v1, v that of v2: the point (1.5, -0.375, 5).
  h = hit_one(make_ray({1.5f, -1, 0}, {0, 0.125f, 1}), a, b, c);
  REQUIRE(h);
  CHECK(h->t == 5.0f);
  CHECK(h->u == Approx(0.625f).margin(1e-6));
  CHECK(h->v == Approx(0.15625f).margin(1e-6));
}

TEST_CASE("watertight: general direction reconstructs the hit point", "[watertight]") {
  std::mt19937 g(7);
  for (int i = 0; i < 1000; ++i) {
    const Vec3f a{rand_in(g, -1, 1), rand_in(g, -1, 1), rand_in(g, -1, 1)};
    const Vec3f b{rand_in(g, -1, 1), rand_in(g, -1, 1), rand_in(g, -1, 1)};
    const Vec3f c{rand_in(g, -1, 1), rand_in(g, -1, 1), rand_in(g, -1, 1)};
    const float wu = rand_in(g, 0.05f, 0.45f), wv = rand_in(g, 0.05f, 0.45f);
    const Vec3f p = a * (1 - wu - wv) + b * wu + c * wv;
    const Vec3f o = p + rand_dir(g) * 3.0f;
    const auto h = hit_one(make_ray(o, (p - o) * 0.5f), a, b, c);
    if (std::abs(dot(normalize(cross(b - a, c - a)), normalize(p - o))) < 0.05f) continue;  // grazing
    REQUIRE(h);
    CHECK(h->t == Approx(2.0f).epsilon(1e-4));
    CHECK(h->u == Approx(wu).margin(1e-4));
    CHECK(h->v == Approx(wv).margin(1e-4));
  }
}

TEST_CASE("watertight: segment ends are inclusive, outside misses", "[watertight]") {
  const Vec3f a{-1, -1, 5}, b{3, -1, 5}, c{-1, 3, 5};
  CHECK(hit_one(make_ray({0, 0, 0}, {0, 0, 1}, 5.0f, 5.0f), a, b, c));
  CHECK(hit_one(make_ray({0, 0, 0}, {0, 0, 1}, 0.0f, 5.0f), a, b, c));
  CHECK(hit_one(make_ray({0, 0, 0}, {0, 0, 1}, 5.0f, kInf), a, b, c));
  CHECK_FALSE(hit_one(make_ray({0, 0, 0}, {0, 0, 1}, std::nextafter(5.0f, 6.0f), kInf), a, b, c));
  CHECK_FALSE(hit_one(make_ray({0, 0, 0}, {0, 0, 1}, 0.0f, std::nextafter(5.0f, 0.0f)), a, b, c));
  CHECK_FALSE(hit_one(make_ray({0, 0, 6}, {0, 0, 1}), a, b, c));  // behind the origin
  CHECK(hit_one(make_ray({0, 0, 6}, {0, 0, 1}, -kInf, kInf), a, b, c));  // unless tnear < 0 allows it
  CHECK_FALSE(hit_one(make_ray({5, 5, 0}, {0, 0, 1}), a, b, c));  // outside the triangle
  CHECK_FALSE(hit_one(make_ray({0, 0, 5}, {1, 1, 0}), a, b, c));  // in the plane: det == 0
}

TEST_CASE("watertight: invalid rays miss everywhere", "[watertight]") {
  const Vec3f a{-1, -1, 5}, b{3, -1, 5}, c{-1, 3, 5};
  const std::vector<Ray> bad = {
      make_ray({kNaN, 0, 0}, {0, 0, 1}), make_ray({0, 0, 0}, {0, kNaN, 1}),
      make_ray({kInf, 0, 0}, {0, 0, 1}), make_ray({0, 0, 0}, {0, 0, kInf}),
      make_ray({0, 0, 0}, {0, 0, -kInf}), make_ray({0, 0, 0}, {0, 0, 0}),
      make_ray({0, 0, 0}, {0, 0, 1}, 6.0f, 4.0f), make_ray({0, 0, 0}, {0, 0, 1}, kNaN, kInf),
      make_ray({0, 0, 0}, {0, 0, 1}, 0.0f, kNaN)};
  TriangleSoup soup;
  add_tri(soup, a, b, c);
  const BruteForceTracer brute(soup);
  for (const Ray& r : bad) {
    CHECK_FALSE(is_valid(r));
    CHECK_FALSE(hit_one(r, a, b, c));
    CHECK_FALSE(brute.trace(r).hit());
  }
  std::vector<Ray> mixed = bad;
  mixed.push_back(make_ray({0, 0, 0}, {0, 0, 1}));  // one valid lane among invalid ones
  check_packets_match(soup, mixed);
}

TEST_CASE("watertight: degenerate triangles are never hit", "[watertight]") {
  // Exactly collinear in the ray's projection: det == 0 in the test itself.
  CHECK_FALSE(hit_one(make_ray({1, 1, -1}, {0, 0, 1}), {0, 0, 0}, {1, 1, 0}, {2, 2, 0}));
  CHECK_FALSE(hit_one(make_ray({1, 1, -1}, {0, 0, 1}), {1, 1, 0}, {1, 1, 0}, {1, 1, 0}));
  // Collinear in 3D but not in float projection: callers skip flagged ones.
  TriangleSoup soup;
  add_tri(soup, {0.1f, 0.2f, 0.3f}, {1.1f, 1.3f, 1.7f}, {2.1f, 2.4f, 3.1f});
  add_tri(soup, {-1, -1, 5}, {3, -1, 5}, {-1, 3, 5});
  soup.degenerate[0] = 1;
  const BruteForceTracer brute(soup);
  const Vec3f mid{1.1f, 1.3f, 1.7f};
  for (const Vec3f o : {Vec3f{0, 0, -3}, Vec3f{5, -2, 1}, Vec3f{-3, 4, 2}}) {
    const Hit h = brute.trace(make_ray(o, mid - o));
    CHECK(h.prim != 0);
  }
  RayCounters c;
  brute.trace(make_ray({0, 0, 0}, {0, 0, 1}), &c);
  CHECK(c.rays == 1);
  CHECK(c.triangle_tests == 1);
}

TEST_CASE("watertight: rays through shared edges and the centre of a closed fan", "[watertight]") {
  const Vec3f centre{1, 2, 3};
  const TriangleSoup fan = make_fan(centre);
  const BruteForceTracer brute(fan);
  std::vector<Ray> all;
  for (int s : {1, -1})
    for (int px = -2; px <= 2; ++px)
      for (int py = -2; py <= 2; ++py) {
        const Vec3f o = centre + kFanNormal * float(6 * s) + Vec3f{float(px), float(py), float(px - py)};
        // Exactly through the centre vertex (integer arithmetic is exact).
        Ray r = make_ray(o, centre - o);
        Hit h = brute.trace(r);
        REQUIRE(h.hit());
        CHECK(h.t == Approx(1.0f).epsilon(1e-6));
        all.push_back(r);
        // Exactly through the midpoint of each spoke (shared by triangles k-1 and k).
        for (std::uint32_t k = 0; k < 8; ++k) {
          const Vec3f p = centre + (fan.vertices[1 + k] - centre) * 0.5f;
          r = make_ray(o, p - o);
          h = brute.trace(r);
          INFO("spoke " << k << " origin " << o.x << " " << o.y << " " << o.z);
          REQUIRE(h.hit());
          CHECK(h.t == Approx(1.0f).epsilon(1e-6));
          CHECK((h.prim == k || h.prim == (k + 7) % 8));
          all.push_back(r);
        }
      }
  // Rays aimed at the centre from random origins (direction rounded).
  std::mt19937 g(11);
  for (int i = 0; i < 2000; ++i) {
    const Vec3f d = normalize(kFanNormal) + rand_dir(g) * 0.5f;  // within 30 degrees of the normal
    const Vec3f o = centre + d * rand_in(g, 0.5f, 50.0f) * (i % 2 ? 1.0f : -1.0f);
    const Ray r = make_ray(o, centre - o);
    const Hit h = brute.trace(r);
    INFO("ray " << i);
    REQUIRE(h.hit());
    CHECK(h.t == Approx(1.0f).epsilon(1e-5));
    all.push_back(r);
  }
  check_packets_match(fan, all);
}

TEST_CASE("watertight: closed solids never leak, even through vertices", "[watertight]") {
  std::mt19937 g(3);
  for (const TriangleSoup& solid : {make_tetra(), make_cube()}) {
    const bool tetra = solid.size() == 4;
    const BruteForceTracer brute(solid);
    std::vector<Ray> rays;
    // Exact aims at vertices and edge midpoints from dyadic interior points.
    const Vec3f origins_tet[] = {{1, 1, 1}, {0.5f, 0.25f, 1.5f}, {2, 0.5f, 0.75f}};
    const Vec3f origins_cube[] = {{0, 0, 0}, {0.5f, 0.25f, -0.125f}, {-0.75f, 0.5f, 0.5f}};
    for (const Vec3f& o : tetra ? origins_tet : origins_cube) {
      for (const TriIndices& t : solid.triangles)
        for (int k = 0; k < 3; ++k) {
          const Vec3f v = solid.vertices[t[k]], w = solid.vertices[t[(k + 1) % 3]];
          for (const Vec3f p : {v, (v + w) * 0.5f}) {
            const Hit h = brute.trace(make_ray(o, p - o));
            REQUIRE(h.hit());
            CHECK(h.t == Approx(1.0f).epsilon(1e-6));
            rays.push_back(make_ray(o, p - o));
          }
        }
    }
    // Random interior origins: random directions and rounded aims at vertices.
    std::size_t leaks = 0;
    for (int i = 0; i < 5000; ++i) {
      Vec3f o = tetra ? Vec3f{rand_in(g, 0.01f, 1.3f), rand_in(g, 0.01f, 1.3f), rand_in(g, 0.01f, 1.3f)}
                      : Vec3f{rand_in(g, -0.99f, 0.99f), rand_in(g, -0.99f, 0.99f), rand_in(g, -0.99f, 0.99f)};
      const Vec3f target = solid.vertices[std::size_t(i) % solid.vertices.size()];
      const Ray r = make_ray(o, i % 2 ? rand_dir(g) : target - o);
      leaks += brute.trace(r).hit() ? 0 : 1;
      rays.push_back(r);
    }
    CHECK(leaks == 0);
    check_packets_match(solid, rays);
  }
}

TEST_CASE("watertight: packets equal single rays on a random soup", "[watertight][packet]") {
  std::mt19937 g(42);
  TriangleSoup soup = random_soup(g, 300, 0.3f);
  // A degenerate one in the middle of it all, flagged as the loader would.
  add_tri(soup, {-1, -1, -1}, {0, 0, 0}, {1, 1, 1});
  soup.degenerate.back() = 1;
  std::vector<Ray> rays;
  for (int i = 0; i < 3000; ++i) {
    const Vec3f o{rand_in(g, -2, 2), rand_in(g, -2, 2), rand_in(g, -2, 2)};
    rays.push_back(make_ray(o, rand_dir(g), i % 5 == 0 ? 0.5f : 0.0f, i % 7 == 0 ? 1.5f : kInf));
  }
  // Coherent rays (one dominant axis for the whole packet: the uniform path).
  for (int i = 0; i < 1000; ++i)
    rays.push_back(make_ray({rand_in(g, -1, 1), rand_in(g, -1, 1), -3}, {rand_in(g, -0.2f, 0.2f), rand_in(g, -0.2f, 0.2f), 1}));
  rays.push_back(make_ray({0, 0, 0}, {0, 0, 0}));  // invalid, and the batch is not a multiple of 16
  check_packets_match(soup, rays);
  CHECK(brute_hits(soup, rays) > rays.size() / 10);
}

TEST_CASE("watertight: packets mixing invalid lanes and tied axes equal single rays", "[watertight][packet]") {
  // The packet precomputation runs on vectors: the dominant axis must follow
  // max_axis exactly where |dir| components tie, the winding swap where
  // dir[kz] < 0, and invalid lanes must not disturb their valid neighbours.
  std::mt19937 g(7);
  const TriangleSoup soup = random_soup(g, 200, 0.4f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<Ray> invalid = {
      make_ray({nan, 0, 0}, {1, 0, 0}),          make_ray({0, 0, 0}, {kInf, 1, 0}),
      make_ray({0, 0, 0}, {0, 0, 0}),            make_ray({0, 0, 0}, {1, 1, 1}, 2.0f, 1.0f),
      make_ray({0, 0, 0}, {1, 1, 1}, nan, kInf), make_ray({0, 0, 0}, {1, 1, 1}, 0.0f, nan)};
  std::vector<Ray> rays;
  std::size_t tied = 0;
  for (int i = 0; i < 4000; ++i) {
    // Components drawn from {±a, ±b, 0} so that two or three magnitudes tie.
    const float a = rand_in(g, 0.2f, 1.0f), b = rand_in(g, 0.2f, 1.0f);
    const float pool[5] = {a, -a, b, -b, 0.0f};
    Vec3f d{pool[g() % 5], pool[g() % 5], pool[g() % 5]};
    if (d.x == 0 && d.y == 0 && d.z == 0) d.z = -a;
    const float m[3] = {std::abs(d.x), std::abs(d.y), std::abs(d.z)};
    tied += (m[0] == m[1] || m[0] == m[2] || m[1] == m[2]) ? 1 : 0;
    const Vec3f o{rand_in(g, -1, 1), rand_in(g, -1, 1), rand_in(g, -1, 1)};
    rays.push_back(make_ray(o - d * 3.0f, d));
    if (i % 3 == 0) rays.push_back(invalid[std::size_t(i / 3) % invalid.size()]);
  }
  CHECK(tied > 2000);
  check_packets_match(soup, rays);
  CHECK(brute_hits(soup, rays) > rays.size() / 10);
  CHECK(brute_hits(soup, invalid) == 0);
}

TEST_CASE("watertight: batch widths are checked", "[watertight][packet]") {
  TriangleSoup soup = make_tetra();
  std::vector<Ray> rays(5, make_ray({1, 1, 1}, {1, 0, 0}));
  std::vector<Hit> hits(5);
  CHECK_THROWS_AS(brute_force_trace_batch(soup, rays, hits, 3, nullptr), UsageError);
  std::vector<Hit> few(4);
  CHECK_THROWS_AS(brute_force_trace_batch(soup, rays, few, 4, nullptr), UsageError);
  for (int w : {1, 4, 8, 16}) {
    brute_force_trace_batch(soup, rays, hits, w, nullptr);
    for (const Hit& h : hits) CHECK(h.t == 1.0f);  // the face x + y + z = 4
  }
}

namespace {

/// edges_double_lanes<W> against watertight_edges_double lane by lane, bits
/// compared: random floats of all magnitudes (subnormal to near overflow),
/// small integers whose products cancel exactly, and lanes left alone.
template <int W>
void check_vector_double_fallback(std::mt19937& g) {
  using simd::vfloat;
  using simd::vmask;
  std::uniform_int_distribution<int> kind(0, 3), small(-4, 4), expo(-150, 126), coin(0, 1);
  const auto value = [&](int k) -> float {
    if (k == 0) return float(small(g));                                        // exact zeros and cancellations
    if (k == 1) return std::ldexp(rand_in(g, -1, 1), expo(g));                 // any magnitude
    if (k == 2) return rand_in(g, -1, 1) * 0x1p-140f;                          // subnormal
    return rand_in(g, -1, 1);
  };
  std::size_t zeros = 0;
  for (int round = 0; round < 2000; ++round) {
    vfloat<W> in[6], u, v, w;
    vmask<W> need{};
    for (int i = 0; i < W; ++i) {
      const int k = kind(g);
      for (auto& x : in) x[i] = value(k);
      u[i] = rand_in(g, -1, 1), v[i] = rand_in(g, -1, 1), w[i] = rand_in(g, -1, 1);
      need[i] = coin(g) ? -1 : 0;
    }
    vfloat<W> gu = u, gv = v, gw = w;
    simd::watertight_detail::edges_double_lanes<W>(need, in[0], in[1], in[2], in[3], in[4], in[5], gu, gv, gw);
    for (int i = 0; i < W; ++i) {
      float eu = u[i], ev = v[i], ew = w[i];
      if (need[i]) watertight_edges_double(in[0][i], in[1][i], in[2][i], in[3][i], in[4][i], in[5][i], eu, ev, ew);
      const float got[3] = {gu[i], gv[i], gw[i]}, want[3] = {eu, ev, ew};
      REQUIRE(std::memcmp(got, want, sizeof got) == 0);
      zeros += need[i] && (eu == 0.0f || ev == 0.0f || ew == 0.0f);
    }
  }
  CHECK(zeros > 100);  // exact zeros were among the cases
}

}  // namespace

TEST_CASE("watertight: the vector double fallback equals the scalar one", "[watertight]") {
  std::mt19937 g(7);
  check_vector_double_fallback<4>(g);
  check_vector_double_fallback<8>(g);
  check_vector_double_fallback<16>(g);
}
