/// \file test_exact_leaf.cpp
/// The staged exact leaf test (robust/certified_intersector.h) against a
/// reference written the plain way, in CGAL::Exact_rational: the Plücker signs,
/// t = n·(v0 - o) / n·d as a rational, its nearest float (robust/nearest_float.h),
/// a miss beyond the float range, and ties to the lower triangle number. Random
/// triangles and rays, rays exactly through vertices and edges, coplanar
/// duplicates, huge and tiny coordinates.
#include <CGAL/Exact_rational.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "geometry/core/triangle_soup.h"
#include "robust/certified_intersector.h"
#include "robust/degenerate.h"
#include "robust/nearest_float.h"
#include "robust/exact_sum.h"
#include "traverse/exact_double_stage.h"
#include "test_util.h"

namespace bsprt {
namespace {

using Q = CGAL::Exact_rational;
using Q3 = std::array<Q, 3>;

Q3 q3(const Vec3f& a) { return {Q(double(a.x)), Q(double(a.y)), Q(double(a.z))}; }
Q3 qsub(const Q3& a, const Q3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Q qdot(const Q3& a, const Q3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Q3 qcross(const Q3& a, const Q3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

/// The reference decision: the exact t of a hit in [tnear, tfar] (finite as a
/// float), else nullopt.
std::optional<Q> reference_t(const Ray& r, const std::array<Vec3f, 3>& tri) {
  const Q3 o = q3(r.org), d = q3(r.dir), a0 = qsub(q3(tri[0]), o), a1 = qsub(q3(tri[1]), o), a2 = qsub(q3(tri[2]), o);
  const int s[3] = {CGAL::sign(qdot(qcross(a1, a2), d)), CGAL::sign(qdot(qcross(a2, a0), d)),
                    CGAL::sign(qdot(qcross(a0, a1), d))};
  const bool neg = s[0] < 0 || s[1] < 0 || s[2] < 0, pos = s[0] > 0 || s[1] > 0 || s[2] > 0;
  if ((neg && pos) || !(neg || pos)) return std::nullopt;
  const Q3 n = qcross(qsub(q3(tri[1]), q3(tri[0])), qsub(q3(tri[2]), q3(tri[0])));
  const Q t = qdot(n, a0) / qdot(n, d);
  if (r.tnear == std::numeric_limits<float>::infinity() || r.tfar == -std::numeric_limits<float>::infinity())
    return std::nullopt;  // no finite t in [+inf, +inf] or [-inf, -inf]
  if (std::isfinite(r.tnear) && t < Q(double(r.tnear))) return std::nullopt;
  if (std::isfinite(r.tfar) && t > Q(double(r.tfar))) return std::nullopt;
  if (nearest_float(t) == std::numeric_limits<float>::infinity()) return std::nullopt;
  return t;
}

/// The reference nearest hit over `prims`: exact t, ties to the lower number.
Hit reference_nearest(const TriangleSoup& s, const Ray& r, const std::vector<std::uint32_t>& prims) {
  std::optional<Q> best;
  Hit h;
  for (const std::uint32_t p : prims) {
    const std::optional<Q> t = reference_t(r, s.corners(p));
    if (!t) continue;
    if (!best || *t < *best || (*t == *best && p < h.prim)) best = t, h.prim = p;
  }
  if (best) h.t = nearest_float(*best);
  return h;
}

TriangleSoup soup_of(const std::vector<std::array<Vec3f, 3>>& tris) {
  TriangleSoup s;
  for (const auto& t : tris) {
    const auto base = std::uint32_t(s.vertices.size());
    s.vertices.insert(s.vertices.end(), t.begin(), t.end());
    s.triangles.push_back({base, base + 1, base + 2});
  }
  classify_degenerate(s);
  return s;
}

Hit staged_nearest(const CertifiedIntersector& c, const Ray& r, const std::vector<std::uint32_t>& prims,
                   RayCounters* counters = nullptr) {
  NearestHit best;
  c.intersect(r, prims, best, counters);
  return best.hit;
}

void require_same(const Hit& got, const Hit& want) {
  REQUIRE(got.prim == want.prim);
  if (want.hit()) REQUIRE(got.t == want.t);
}

Ray make_ray(Vec3f o, Vec3f d, float tnear = 0.0f, float tfar = std::numeric_limits<float>::infinity()) {
  Ray r;
  r.org = o;
  r.dir = d;
  r.tnear = tnear;
  r.tfar = tfar;
  return r;
}

}  // namespace

TEST_CASE("exact leaf test: random triangles and rays equal the rational reference, no exact stage",
          "[exact][exact-leaf]") {
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  auto p = [&] { return Vec3f{u(rng), u(rng), u(rng)}; };
  std::vector<std::array<Vec3f, 3>> tris;
  for (int i = 0; i < 64; ++i) tris.push_back({p(), p(), p()});
  const TriangleSoup s = soup_of(tris);
  const CertifiedIntersector c(s);
  std::vector<std::uint32_t> all;
  for (std::uint32_t i = 0; i < s.size(); ++i)
    if (!s.is_degenerate(i)) all.push_back(i);
  RayCounters counters;
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    // Aimed at a random point of a random triangle (most rays hit), or random.
    const Vec3f o = Vec3f{u(rng), u(rng), u(rng)} * 3.0f;
    const auto& t = tris[std::size_t(i) % tris.size()];
    const float a = 0.5f * (u(rng) + 1.0f), b = 0.5f * (u(rng) + 1.0f) * (1.0f - a);
    const Vec3f target = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b;
    const Ray r = make_ray(o, i % 4 == 0 ? p() : target - o, i % 3 == 0 ? -1.0f : 0.0f,
                           i % 5 == 0 ? 1.5f : std::numeric_limits<float>::infinity());
    const Hit want = reference_nearest(s, r, all);
    hits += want.hit();
    require_same(staged_nearest(c, r, all, &counters), want);
  }
  CHECK(hits > 500);
  CHECK(counters.exact_decisions == 0);  // random data never needs more than the filter
}

TEST_CASE("exact leaf test: signs from the filter and from the exact stage mix correctly", "[exact][exact-leaf]") {
  // The filter works on the sheared ray (its 2D cross products have the
  // Plücker volumes' signs); the exact stage on the Plücker volumes. Forcing
  // some weights through the exact stage mixes the two on one triangle.
  std::mt19937 rng(31);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  auto p = [&] { return Vec3f{u(rng), u(rng), u(rng)}; };
  std::vector<std::array<Vec3f, 3>> tris;
  for (int i = 0; i < 16; ++i) tris.push_back({p(), p(), p()});
  const TriangleSoup s = soup_of(tris);
  const CertifiedIntersector c(s);
  std::vector<std::uint32_t> all;
  for (std::uint32_t i = 0; i < s.size(); ++i)
    if (!s.is_degenerate(i)) all.push_back(i);
  std::vector<Ray> rays;
  for (int i = 0; i < 600; ++i) {
    const auto& t = tris[std::size_t(i) % tris.size()];
    const Vec3f o = p() * 3.0f, target = (t[0] + t[1] + t[2]) * (1.0f / 3.0f) + p() * 0.2f;
    Vec3f d = target - o;
    if (i % 2) d = Vec3f{-d.x, d.y, -d.z};  // every sign of the dominant axis
    rays.push_back(make_ray(o, d, -10.0f));
  }
  for (const unsigned weights : {1u, 2u, 4u, 5u, 6u, 7u}) {
    CAPTURE(weights);
    CertifiedIntersector::set_filter_off_for_testing(weights);
    RayCounters counters;
    int hits = 0;
    for (const Ray& r : rays) {
      const Hit want = reference_nearest(s, r, all);
      hits += want.hit();
      require_same(staged_nearest(c, r, all, &counters), want);
    }
    CertifiedIntersector::set_filter_off_for_testing(0);
    CHECK(hits > 100);
    CHECK(counters.exact_decisions > 0);
  }
}

TEST_CASE("exact leaf test: rays exactly through vertices and edges of a fan equal the reference",
          "[exact][exact-leaf]") {
  // A closed fan around a vertex: six triangles sharing v = (0.3, 0.2, 0.7)
  // and the edges to its ring, tilted so nothing is axis-aligned.
  const Vec3f v{0.3f, 0.2f, 0.7f};
  std::vector<Vec3f> ring;
  for (int k = 0; k < 6; ++k) {
    const float a = float(k) * 1.0471976f;
    ring.push_back({0.3f + std::cos(a), 0.2f + std::sin(a), 0.7f + 0.25f * std::cos(2 * a + 0.5f)});
  }
  std::vector<std::array<Vec3f, 3>> tris;
  for (int k = 0; k < 6; ++k) tris.push_back({v, ring[k], ring[(k + 1) % 6]});
  const TriangleSoup s = soup_of(tris);
  const CertifiedIntersector c(s);
  const std::vector<std::uint32_t> all = {5, 3, 1, 0, 2, 4};  // out of order: ties must still go to 0
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  RayCounters counters;
  int through_vertex = 0;
  for (int i = 0; i < 400; ++i) {
    const Vec3f o{u(rng), u(rng), 3.0f + u(rng)};
    // Aim at the shared vertex, at a ring vertex or at an edge's midpoint
    // (exact in float for these coordinates only sometimes: both kinds occur).
    Vec3f target = v;
    if (i % 3 == 1) target = ring[i % 6];
    if (i % 3 == 2) target = (v + ring[i % 6]) * 0.5f;
    const Ray r = make_ray(o, target - o);
    through_vertex += (i % 3 == 0) && (o + (target - o)).x == v.x;
    require_same(staged_nearest(c, r, all, &counters), reference_nearest(s, r, all));
  }
  CHECK(through_vertex > 0);
  CHECK(counters.rule_decisions > 0);  // exact zeros and ties decided by the rules
}

TEST_CASE("exact leaf test: coplanar duplicates with reversed winding tie by rule to the lower number",
          "[exact][exact-leaf]") {
  std::vector<std::array<Vec3f, 3>> tris;
  const std::array<Vec3f, 3> t{Vec3f{0, 0, 1}, Vec3f{1, 0.1f, 1.2f}, Vec3f{0.1f, 1, 0.9f}};
  tris.push_back({t[0], t[2], t[1]});  // 0: reversed copy
  tris.push_back(t);                   // 1
  const TriangleSoup s = soup_of(tris);
  const CertifiedIntersector c(s);
  const std::vector<std::uint32_t> order = {1, 0};
  RayCounters counters;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.05f, 0.4f);
  for (int i = 0; i < 200; ++i) {
    const Ray r = make_ray({u(rng), u(rng), -1.0f}, {0.01f * u(rng), 0.02f, 1.0f});
    const Hit want = reference_nearest(s, r, order);
    REQUIRE(want.prim == 0);
    require_same(staged_nearest(c, r, order, &counters), want);
  }
  CHECK(counters.exact_decisions == 0);
  CHECK(counters.rule_decisions == 200);
}

// Found on conference camera rays (issue #23): 97 of the 98 exact decisions of
// 90K rays were ties between overlapping triangles in one axis-aligned plane
// (a panel on the ceiling, z = 595.246), with no corner in common. Such a pair
// now ties by rule. An exactly coplanar pair in a slanted plane still needs
// the exact stage, and a pair one float step out of one plane is not a tie.
TEST_CASE("exact leaf test: overlapping triangles in one axis-aligned plane tie by rule to the lower number",
          "[exact][exact-leaf][regression]") {
  const float c = 595.246f;
  std::mt19937 rng(97);
  std::uniform_real_distribution<float> u(0.3f, 0.6f);
  for (int k = 0; k < 3; ++k) {
    const auto at = [&](float a, float b, float h) {  // (a, b) in the plane, h on axis k
      Vec3f p;
      p[k] = h, p[(k + 1) % 3] = a, p[(k + 2) % 3] = b;
      return p;
    };
    for (const float h2 : {c, std::nextafter(c, 1e9f)}) {  // the same plane, then one step above it
      // 0: a large triangle; 1: a smaller one on it, with no corner in common.
      const TriangleSoup s = soup_of({{at(-2.0f, -2.0f, c), at(6.0f, -2.0f, c), at(-2.0f, 6.0f, c)},
                                      {at(0.1f, 0.1f, h2), at(1.5f, 0.15f, h2), at(0.15f, 1.5f, h2)}});
      const CertifiedIntersector ci(s);
      RayCounters counters;
      int ties = 0;
      for (int i = 0; i < 200; ++i) {
        const Vec3f target = at(u(rng), u(rng), c);
        Vec3f o = at(u(rng) - 0.5f, u(rng), c - 10.0f);
        if (i % 2) o[k] = c + 10.0f;  // from either side
        const Ray r = make_ray(o, target - o);
        for (const std::vector<std::uint32_t>& order : {std::vector<std::uint32_t>{1, 0}, {0, 1}}) {
          const Hit want = reference_nearest(s, r, order);
          REQUIRE(want.hit());
          require_same(staged_nearest(ci, r, order, &counters), want);
          ties += want.prim == 0 && h2 == c;
        }
      }
      INFO("axis " << k << (h2 == c ? ", one plane" : ", one step apart"));
      if (h2 == c) {
        CHECK(ties == 400);  // every ray hits both at one t: the lower number wins
        CHECK(counters.exact_decisions == 0);
        CHECK(counters.rule_decisions >= 400);
      } else {
        CHECK(counters.rule_decisions == 0);  // not one plane: no rule applies
      }
    }
  }
  // Exactly coplanar in the slanted plane x + y = 1 (dyadic corners), which
  // contains the z axis: the tie is real, and the rule for planes along an
  // axis settles it (the ray's direction, projected along z, crosses the line
  // x + y = 1).
  {
    const TriangleSoup s = soup_of({{Vec3f{0.0f, 1.0f, -2.0f}, Vec3f{1.0f, 0.0f, -2.0f}, Vec3f{0.5f, 0.5f, 3.0f}},
                                    {Vec3f{0.25f, 0.75f, 0.0f}, Vec3f{0.75f, 0.25f, 0.0f}, Vec3f{0.5f, 0.5f, 1.0f}}});
    const CertifiedIntersector ci(s);
    RayCounters counters;
    const Ray r = make_ray({2.0f, 2.0f, 0.25f}, {-1.5f, -1.5f, 0.0f});
    for (const std::vector<std::uint32_t>& order : {std::vector<std::uint32_t>{1, 0}, {0, 1}}) {
      const Hit want = reference_nearest(s, r, order);
      REQUIRE(want.prim == 0);
      require_same(staged_nearest(ci, r, order, &counters), want);
    }
    CHECK(counters.exact_decisions == 0);
    CHECK(counters.rule_decisions >= 1);
  }
  // Exactly coplanar in x + y + z = 1, a plane along no axis: only the exact stage can tell.
  {
    const TriangleSoup s = soup_of({{Vec3f{2.0f, -1.0f, 0.0f}, Vec3f{-1.0f, 2.0f, 0.0f}, Vec3f{0.0f, -1.0f, 2.0f}},
                                    {Vec3f{0.5f, 0.25f, 0.25f}, Vec3f{0.25f, 0.5f, 0.25f}, Vec3f{0.25f, 0.25f, 0.5f}}});
    const CertifiedIntersector ci(s);
    RayCounters counters;
    const Vec3f o{2.0f, 2.0f, 0.375f};
    const Ray r = make_ray(o, Vec3f{0.3125f, 0.3125f, 0.375f} - o);
    for (const std::vector<std::uint32_t>& order : {std::vector<std::uint32_t>{1, 0}, {0, 1}}) {
      const Hit want = reference_nearest(s, r, order);
      REQUIRE(want.prim == 0);
      require_same(staged_nearest(ci, r, order, &counters), want);
    }
    CHECK(counters.exact_decisions > 0);
  }
}

TEST_CASE("exact leaf test: degenerate rays and extreme coordinates equal the reference", "[exact][exact-leaf]") {
  std::vector<std::array<Vec3f, 3>> tris = {
      {Vec3f{-1, -1, 1}, Vec3f{3, -1, 1}, Vec3f{-1, 3, 1}},                          // 0: z = 1
      {Vec3f{-1, -1, 0x1p100f}, Vec3f{3, -1, 0x1p100f}, Vec3f{-1, 3, 0x1p100f}},     // 1: far away
      {Vec3f{1e-30f, 0, 2}, Vec3f{0, 1e-30f, 2}, Vec3f{-1e-30f, -1e-30f, 2}},        // 2: tiny
      {Vec3f{0, 0, 3}, Vec3f{1, 0, 3}, Vec3f{0, 0, 4}},                              // 3: in the plane y = 0
  };
  const TriangleSoup s = soup_of(tris);
  const CertifiedIntersector c(s);
  const std::vector<std::uint32_t> all = {0, 1, 2, 3};
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<Ray> rays = {
      make_ray({0.25f, 0.25f, 0}, {0, 0, 1e-40f}),          // beyond the float range: a miss
      make_ray({0.25f, 0.25f, 2}, {0, 0, 0x1p-27f}),        // t near 2^127: finite
      make_ray({0, 0, 0}, {0, 0, 1}, 1.5f),                  // through the tiny triangle's inside
      make_ray({1e-30f, 0, 0}, {0, 0, 1}, 1.5f),             // exactly through its vertex
      make_ray({0.5f, 0, 0}, {0, 0, 1}, 2.5f),               // in the plane of triangle 3: a miss there
      make_ray({0.25f, 0, 3.5f}, {0, 1, 0}, -inf, inf),      // through triangle 3's inside, whole line
      make_ray({0, 0, 0}, {0, 0, 1}, 1.0f, 1.0f),            // t = tnear = tfar = 1 on triangle 0
      make_ray({-1, -1, 0}, {0, 0, 1}),                      // exactly through corners of 0 and 1
      make_ray({1, 1, 0}, {0, 0, 1}),                        // exactly on the hypotenuse of triangle 0
  };
  for (std::size_t i = 0; i < rays.size(); ++i) {
    CAPTURE(i);
    require_same(staged_nearest(c, rays[i], all), reference_nearest(s, rays[i], all));
  }
  CHECK(!staged_nearest(c, rays[0], all).hit());
  CHECK(staged_nearest(c, rays[1], all).t == 0x1p127f);
  CHECK(staged_nearest(c, rays[6], all).prim == 0);
}

TEST_CASE("exact leaf test: ties in t at midpoints of floats round to even, as the reference", "[exact][exact-leaf]") {
  // t = z / 1 for a ray from the origin along +z to a plane z = c: choose c
  // as a double midpoint between two floats by making the plane slanted so
  // that t is exactly (1 + 2^-24) (between 1 and 1 + 2^-23).
  // Triangle through (0,0,1) with normal (0,0,1) tilted: with o = (0, 0, -2^-24)
  // and d = (0, 0, 1), t = 1 + 2^-24 exactly, a midpoint: ties to even gives 1.
  const std::vector<std::array<Vec3f, 3>> tris = {{Vec3f{-1, -1, 1}, Vec3f{3, -1, 1}, Vec3f{-1, 3, 1}}};
  const TriangleSoup s = soup_of(tris);
  const CertifiedIntersector c(s);
  const std::vector<std::uint32_t> all = {0};
  for (const float z0 : {-0x1p-24f, -0x3p-24f, -0x1p-25f}) {
    const Ray r = make_ray({0, 0, z0}, {0, 0, 1});
    CAPTURE(z0);
    require_same(staged_nearest(c, r, all), reference_nearest(s, r, all));
  }
  CHECK(staged_nearest(c, make_ray({0, 0, -0x1p-24f}, {0, 0, 1}), all).t == 1.0f);
}


namespace {

/// Both ways of testing a ray against a sequence of leaves: the intersector
/// alone, and detail::exact_leaf_staged (the traversals' inline double stage).
/// Every field of the nearest hit and every counter must agree after each leaf.
void require_staged_equals_intersector(const CertifiedIntersector& c, const TriangleSoup& s, const Ray& r,
                                       const std::vector<std::vector<std::uint32_t>>& leaves,
                                       RayCounters& staged_counters) {
  NearestHit a, b;
  RayCounters ca, cb;
  const detail::ExactRayConst fr = detail::exact_ray_const(r);
  for (const auto& leaf : leaves) {
    std::vector<LeafTriangle> corners;
    for (const std::uint32_t p : leaf) corners.push_back({s.corner(p, 0), s.corner(p, 1), s.corner(p, 2)});
    c.intersect(r, leaf, corners.data(), a, &ca);
    detail::exact_leaf_staged(c, r, fr, leaf.data(), corners.data(), std::uint32_t(leaf.size()), b, &cb);
    REQUIRE(b.hit.prim == a.hit.prim);
    REQUIRE(std::bit_cast<std::uint32_t>(b.hit.t) == std::bit_cast<std::uint32_t>(a.hit.t));
    REQUIRE(std::bit_cast<std::uint32_t>(b.hit.u) == std::bit_cast<std::uint32_t>(a.hit.u));
    REQUIRE(std::bit_cast<std::uint32_t>(b.hit.v) == std::bit_cast<std::uint32_t>(a.hit.v));
    REQUIRE(b.t_lo == a.t_lo);
    REQUIRE(b.t_hi == a.t_hi);
    REQUIRE(b.on == a.on);
    if (a.hit.hit()) REQUIRE(b.tri == a.tri);
    if (a.on != 0) {
      REQUIRE((b.p.x == a.p.x && b.p.y == a.p.y && b.p.z == a.p.z));
      REQUIRE((b.q.x == a.q.x && b.q.y == a.q.y && b.q.z == a.q.z));
    }
    REQUIRE(cb.triangle_tests == ca.triangle_tests);
    REQUIRE(cb.rule_decisions == ca.rule_decisions);
    REQUIRE(cb.exact_decisions == ca.exact_decisions);
  }
  staged_counters.triangle_tests += cb.triangle_tests;
  staged_counters.exact_decisions += cb.exact_decisions;
  staged_counters.rule_decisions += cb.rule_decisions;
}

}  // namespace

TEST_CASE("staged exact leaf: equals the certified intersector, field for field and counter for counter",
          "[exact][exact-leaf]") {
  // A mix that reaches every branch: random triangles (the double stage
  // decides), a closed fan with rays through its vertices and edges (rules
  // and the exact stage), coplanar duplicates with reversed winding (ties),
  // a collinear and a non-finite triangle (never hit), the same triangle in
  // two leaves, and rays whose t lies at tnear or tfar.
  std::mt19937 rng(2026);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  auto p = [&] { return Vec3f{u(rng), u(rng), u(rng)}; };
  std::vector<std::array<Vec3f, 3>> tris;
  for (int i = 0; i < 40; ++i) tris.push_back({p(), p(), p()});
  const Vec3f v{0.3f, 0.2f, 0.7f};
  std::vector<Vec3f> ring;
  for (int k = 0; k < 6; ++k) {
    const float a = float(k) * 1.0471976f;
    ring.push_back({0.3f + 0.5f * std::cos(a), 0.2f + 0.5f * std::sin(a), 0.7f + 0.1f * std::cos(2 * a + 0.5f)});
  }
  for (int k = 0; k < 6; ++k) tris.push_back({v, ring[k], ring[(k + 1) % 6]});
  tris.push_back({tris[3][0], tris[3][2], tris[3][1]});  // reversed copy of triangle 3
  tris.push_back({Vec3f{0, 0, 0}, Vec3f{1, 1, 1}, Vec3f{2, 2, 2}});  // collinear
  tris.push_back({Vec3f{0, 0, 0.5f}, Vec3f{std::numeric_limits<float>::infinity(), 0, 0.5f}, Vec3f{0, 1, 0.5f}});
  const TriangleSoup s = soup_of(tris);
  REQUIRE(s.degenerate_count() == 2);
  const CertifiedIntersector c(s);
  REQUIRE(c.staged());
  std::vector<std::uint32_t> all(s.size());
  std::vector<std::uint32_t> live;
  for (std::uint32_t i = 0; i < s.size(); ++i) {
    all[i] = i;
    if (!s.is_degenerate(i)) live.push_back(i);
  }
  RayCounters counters;
  int hits = 0;
  for (int i = 0; i < 3000; ++i) {
    const Vec3f o = p() * 3.0f;
    Vec3f target;
    switch (i % 4) {
      case 0: target = v; break;                               // the fan's shared vertex
      case 1: target = ring[std::size_t(i) % 6]; break;        // a ring vertex
      case 2: target = (v + ring[std::size_t(i) % 6]) * 0.5f; break;  // an edge
      default: {
        const auto& t = tris[std::size_t(i) % 40];
        target = (t[0] + t[1] + t[2]) * (1.0f / 3.0f) + p() * 0.1f;
      }
    }
    Ray r = make_ray(o, target - o, i % 3 == 0 ? -1.0f : 0.0f);
    if (i % 7 == 0) r.tfar = 1.0f;  // t of the aimed point is about 1
    if (i % 11 == 0) r.tnear = 1.0f;
    // Leaves of 1 to 6 triangles, in a random order, with one triangle listed twice.
    std::shuffle(all.begin(), all.end(), rng);
    std::vector<std::vector<std::uint32_t>> leaves;
    for (std::size_t k = 0; k < all.size();) {
      const std::size_t n = std::min<std::size_t>(all.size() - k, 1 + std::size_t(rng() % 6));
      leaves.emplace_back(all.begin() + std::ptrdiff_t(k), all.begin() + std::ptrdiff_t(k + n));
      k += n;
    }
    leaves.push_back({all[0], all[1]});
    require_staged_equals_intersector(c, s, r, leaves, counters);
    const Hit want = reference_nearest(s, r, live);  // the rational reference takes finite corners only
    hits += want.hit();
    NearestHit staged;
    for (const auto& leaf : leaves) {
      std::vector<LeafTriangle> corners;
      for (const std::uint32_t q : leaf) corners.push_back({s.corner(q, 0), s.corner(q, 1), s.corner(q, 2)});
      detail::exact_leaf_staged(c, r, detail::exact_ray_const(r), leaf.data(), corners.data(),
                                std::uint32_t(leaf.size()), staged, nullptr);
    }
    require_same(staged.hit, want);
  }
  CHECK(hits > 1000);
  CHECK(counters.exact_decisions > 0);  // the fan's exact zeros went to the intersector
  CHECK(counters.rule_decisions > 0);
  // A ray through the inside of a random triangle needs no exact decision;
  // with the filter hook on, the staged path must still hand its triangles
  // to the exact stage (it would bypass the hook otherwise).
  const auto& t0 = tris[0];
  const Vec3f o0{0.05f, -0.1f, 3.0f}, aim = (t0[0] + t0[1] + t0[2]) * (1.0f / 3.0f);
  const Ray r = make_ray(o0, aim - o0);
  RayCounters on, off;
  require_staged_equals_intersector(c, s, r, {all}, on);
  CHECK(on.exact_decisions == 0);
  CertifiedIntersector::set_filter_off_for_testing(7);
  require_staged_equals_intersector(c, s, r, {all}, off);
  CertifiedIntersector::set_filter_off_for_testing(0);
  CHECK(off.exact_decisions > 0);
}

}  // namespace bsprt

namespace bsprt {
namespace {

Q plucker(const Vec3f& p, const Vec3f& q, const Ray& r) {  // ((p - o) x (q - o))·d, exactly
  const Q3 o = q3(r.org);
  return qdot(qcross(qsub(q3(p), o), qsub(q3(q), o)), q3(r.dir));
}

}  // namespace

TEST_CASE("exact sum: signs of sums of float products, the axis-edge volume and the on-line test equal Exact_rational's",
          "[exact][exact-leaf]") {
  std::mt19937 rng(1205);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::uniform_int_distribution<int> expo(-60, 60), pick(0, 3);
  std::uniform_real_distribution<float> bary(0.0f, 1.0f);
  const auto rnd = [&] { return std::ldexp(unit(rng), expo(rng)); };
  int zeros = 0;
  for (int i = 0; i < 20000; ++i) {
    // Four products of floats, some cancelling exactly or nearly.
    float a[4], b[4];
    for (int k = 0; k < 4; ++k) a[k] = rnd(), b[k] = rnd();
    const int mode = pick(rng);
    if (mode <= 1) a[1] = -a[0], b[1] = b[0];                                 // a pair that cancels
    if (mode == 0) a[3] = -a[2], b[3] = b[2];                                 // and another: the sum is 0
    if (mode == 1) a[3] = a[2], b[3] = -std::nextafter(b[2], 2.0f * b[2]);  // nearly: one float step
    std::array<double, 4> t;
    Q sum(0);
    for (int k = 0; k < 4; ++k) t[k] = double(a[k]) * double(b[k]), sum += Q(double(a[k])) * Q(double(b[k]));
    double approx;
    const int s = detail::exact_sum_sign(t, approx);
    REQUIRE(s == CGAL::sign(sum));
    REQUIRE((approx > 0) - (approx < 0) == s);
    zeros += s == 0;
  }
  CHECK(zeros > 100);  // the exact zeros were exercised

  // Rule (c) and the edge filter against the exact Plücker volume: axis-parallel
  // edges, rays through them exactly (dyadic coordinates) and near them.
  int decided = 0, exact_zero = 0;
  std::uniform_int_distribution<int> grid(-64, 64), axis(0, 2);
  for (int i = 0; i < 20000; ++i) {
    const int j = axis(rng);
    Vec3f p{grid(rng) * 0.25f, grid(rng) * 0.25f, grid(rng) * 0.25f}, q = p;
    q[j] += float(grid(rng) | 1) * 0.125f;
    Vec3f target = p + (q - p) * (float(grid(rng)) / 64.0f);  // on the edge's line, dyadic: exact
    if (i % 3 == 1) target[(j + 1) % 3] = std::nextafter(target[(j + 1) % 3], 1e9f);  // one step off it
    if (i % 3 == 2) target = target + Vec3f{unit(rng), unit(rng), unit(rng)};          // anywhere
    const Vec3f o{grid(rng) * 0.5f + 0.25f, grid(rng) * 0.5f, grid(rng) * 0.5f + 40.0f};
    const Ray r = make_ray(o, target - o);
    if (!is_valid(r)) continue;
    const int want = CGAL::sign(plucker(p, q, r));
    int s;
    double approx;
    REQUIRE(detail::axis_edge_volume_sign(p, q, r.org, r.dir, s, approx));
    REQUIRE(s == want);
    REQUIRE((approx > 0) - (approx < 0) == s);
    exact_zero += want == 0;
    double vol, bound;
    const int f = detail::edge_volume_filter(p, q, r.org, r.dir, vol, bound);
    if (f != 2) {
      REQUIRE(f == want);
      ++decided;
    }
    // A slanted edge is not rule (c)'s.
    Vec3f q2 = q;
    q2[(j + 1) % 3] += 0.5f;
    REQUIRE_FALSE(detail::axis_edge_volume_sign(p, q2, r.org, r.dir, s, approx));
  }
  CHECK(exact_zero > 3000);
  CHECK(decided > 8000);

  // The edge filter on small slanted edges far from the origin, with full
  // mantissas, and rays aimed at the edge through a rounded direction: the
  // volumes are tiny, and the double evaluation rounds.
  int filter_decided = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3f p{unit(rng) * 100.0f, unit(rng) * 100.0f, unit(rng) * 100.0f};
    const Vec3f q = p + Vec3f{unit(rng), unit(rng), unit(rng)} * 1e-3f;
    const Vec3f o{unit(rng) * 1000.0f, unit(rng) * 1000.0f, unit(rng) * 1000.0f};
    const Ray r = make_ray(o, p + (q - p) * bary(rng) - o);
    double vol, bound;
    const int f = detail::edge_volume_filter(p, q, r.org, r.dir, vol, bound);
    // The error is below 7.1 u M, and the bound is 32 u M.
    const Q exact = plucker(p, q, r), err = Q(vol) - exact;
    REQUIRE(CGAL::abs(err) <= Q(bound) / 4);
    if (f == 2) continue;
    REQUIRE(f == CGAL::sign(exact));
    ++filter_decided;
  }
  CHECK(filter_decided > 15000);

  // The on-line test: points exactly on the line at dyadic t, and one float step off it.
  for (int i = 0; i < 5000; ++i) {
    const Vec3f o{grid(rng) * 0.5f, grid(rng) * 0.5f, grid(rng) * 0.5f};
    const Vec3f d{grid(rng) * 0.25f, grid(rng) * 0.25f, float(grid(rng) | 1) * 0.25f};
    Vec3f p = o + d * (float(grid(rng)) / 8.0f);
    const bool off = i % 2 == 1;
    if (off) p.x = std::nextafter(p.x, 1e9f);
    const Q3 c = qcross(qsub(q3(p), q3(o)), q3(d));
    const bool want = c[0] == 0 && c[1] == 0 && c[2] == 0;
    REQUIRE(detail::on_line_exactly(p, o, d) == want);
    if (!off) REQUIRE(want);
  }
}

TEST_CASE("exact leaf test: rays through axis-parallel edges, through vertices at any t, and ties in planes along an axis "
          "need no exact stage (sponza and conference vertex and edge rays)",
          "[exact][exact-leaf][regression]") {
  // An architectural soup: a floor of axis-aligned squares in z = 0 (two
  // triangles each), a slanted wall in the plane x + y = 4 (it contains the z
  // axis), and a poster on the wall, overlapping it.
  std::vector<std::array<Vec3f, 3>> tris;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const float x = float(i), y = float(j);
      tris.push_back({Vec3f{x, y, 0}, Vec3f{x + 1, y, 0}, Vec3f{x + 1, y + 1, 0}});
      tris.push_back({Vec3f{x, y, 0}, Vec3f{x + 1, y + 1, 0}, Vec3f{x, y + 1, 0}});
    }
  tris.push_back({Vec3f{4, 0, 0}, Vec3f{0, 4, 0}, Vec3f{2, 2, 3}});         // the wall
  tris.push_back({Vec3f{2.5f, 1.5f, 0.5f}, Vec3f{1.5f, 2.5f, 0.5f}, Vec3f{2, 2, 1.5f}});  // the poster
  const TriangleSoup s = soup_of(tris);
  const CertifiedIntersector ci(s);
  std::vector<std::uint32_t> all(s.size());
  for (std::uint32_t i = 0; i < s.size(); ++i) all[i] = i;
  RayCounters counters;
  std::mt19937 rng(46);
  std::uniform_int_distribution<int> g(1, 15), h(1, 7);
  int rays = 0;
  for (int i = 0; i < 3000; ++i) {
    Vec3f target;
    const int kind = i % 3;
    if (kind == 0) target = Vec3f{float(g(rng)) / 4.0f, float(h(rng) % 4), 0.0f};  // on an edge along x
    if (kind == 1) target = Vec3f{float(h(rng) % 4), float(h(rng) % 4), 0.0f};    // a floor vertex
    if (kind == 2) {  // on the poster
      const float a = float(g(rng)) / 32.0f;
      target = Vec3f{2.0f + a, 2.0f - a, 0.75f};
    }
    const Vec3f o{float(g(rng)) - 6.0f, float(g(rng)) - 6.0f, float(h(rng)) + 4.0f};
    // Directions that reach the target at t = 2 or 4, not 1: rule (a) alone would not see the vertex.
    const Ray r = make_ray(o, (target - o) * (i % 2 ? 0.5f : 0.25f));
    // A line coplanar with a slanted edge (its ends differ in two coordinates
    // or three) has an exact zero that none of these rules covers: the wall's
    // foot x + y = 4, the floor's diagonals, the poster's edges, a ray in the
    // wall's plane. The dyadic rays meet such edges often; they are left to
    // the exact stage and not counted here.
    bool slanted_zero = false;
    for (const auto& t : tris)
      for (int e = 0; e < 3; ++e) {
        const Vec3f &p = t[e], &q = t[(e + 1) % 3];
        const int same = int(p.x == q.x) + int(p.y == q.y) + int(p.z == q.z);
        slanted_zero = slanted_zero || (same < 2 && plucker(p, q, r) == 0);
      }
    RayCounters one;
    const Hit want = reference_nearest(s, r, all);
    require_same(staged_nearest(ci, r, all, &one), want);
    if (slanted_zero) continue;
    counters.rule_decisions += one.rule_decisions;
    counters.exact_decisions += one.exact_decisions;
    rays += want.hit();
  }
  CHECK(rays > 1500);
  CHECK(counters.rule_decisions > 1000);
  CHECK(counters.exact_decisions == 0);
  // A pyramid's apex, where only slanted edges meet, hit at t = 2: the
  // on-line test (rule (a) at any t) makes the two volumes at the apex 0, and
  // the four hits tie at the same vertex.
  {
    const Vec3f apex{1.0f, 1.0f, 2.0f};
    const std::vector<std::array<Vec3f, 3>> pyr{{Vec3f{0, 0, 0}, Vec3f{2, 0, 0}, apex},
                                                {Vec3f{2, 0, 0}, Vec3f{2, 2, 0}, apex},
                                                {Vec3f{2, 2, 0}, Vec3f{0, 2, 0}, apex},
                                                {Vec3f{0, 2, 0}, Vec3f{0, 0, 0}, apex}};
    const TriangleSoup ps = soup_of(pyr);
    const CertifiedIntersector pc(ps);
    const std::vector<std::uint32_t> four{0, 1, 2, 3};
    RayCounters apex_counters;
    for (int i = 0; i < 200; ++i) {
      const Vec3f o{float(g(rng)) - 8.0f, float(g(rng)) - 8.0f, float(h(rng)) + 3.0f};
      const Ray r = make_ray(o, (apex - o) * 0.5f);
      const Hit want = reference_nearest(ps, r, four);
      REQUIRE(want.hit());
      require_same(staged_nearest(pc, r, four, &apex_counters), want);
    }
    CHECK(apex_counters.exact_decisions == 0);
    CHECK(apex_counters.rule_decisions >= 200);
  }
  // Exactly through the wall's slanted foot: an exact zero no rule covers.
  RayCounters foot;
  const Vec3f o{-3.0f, -2.0f, 6.0f};
  const Ray r = make_ray(o, (Vec3f{2.5f, 1.5f, 0.0f} - o) * 0.5f);
  require_same(staged_nearest(ci, r, all, &foot), reference_nearest(s, r, all));
  CHECK(foot.exact_decisions > 0);
}

// Shadow rays of the path tracer (issue #23): 0.17 % of sponza's shadow rays
// of bounce 1 reached the exact stage, all to round a t whose enclosure
// straddled a rounding boundary (hits at tiny t near creases). An occluded
// query needs only whether the exact t lies in [tnear, tfar].
TEST_CASE("exact leaf test: any hit takes a t in range without rounding it, nearest hit still rounds exactly",
          "[exact][exact-leaf][regression]") {
  const std::vector<std::array<Vec3f, 3>> tris = {{Vec3f{-1, -1, 1}, Vec3f{3, -1, 1}, Vec3f{-1, 3, 1}}};
  const TriangleSoup s = soup_of(tris);
  const CertifiedIntersector c(s);
  const std::vector<std::uint32_t> prims = {0};
  const std::vector<LeafTriangle> corners = {{tris[0][0], tris[0][1], tris[0][2]}};
  const auto run = [&](const Ray& r, bool any, RayCounters& counters) {
    NearestHit best;
    const detail::ExactRayConst fr = detail::exact_ray_const(r);
    if (any)
      detail::exact_leaf_staged<true>(c, r, fr, prims.data(), corners.data(), 1, best, &counters);
    else
      detail::exact_leaf_staged<false>(c, r, fr, prims.data(), corners.data(), 1, best, &counters);
    return best.hit;
  };
  // t = 1 + 2^-24 and 1 + 3 * 2^-24: midpoints between floats.
  for (const float z0 : {-0x1p-24f, -0x3p-24f}) {
    CAPTURE(z0);
    for (const float tfar : {std::numeric_limits<float>::infinity(), 2.0f, 1.0f + 0x1p-21f, 1.0f}) {
      CAPTURE(tfar);
      const Ray r = make_ray({0, 0, z0}, {0, 0, 1}, 0.0f, tfar);
      const Hit want = reference_nearest(s, r, prims);
      RayCounters nearest_counters, any_counters;
      const Hit nearest = run(r, false, nearest_counters), any = run(r, true, any_counters);
      require_same(nearest, want);
      REQUIRE(any.hit() == want.hit());
      CHECK(any_counters.exact_decisions == 0);
      if (want.hit()) CHECK(nearest_counters.exact_decisions == 1);  // the rounding needs the exact stage
    }
  }
  // A t that rounds past the float range is a miss for any hit too: the
  // any-hit test of one ray against a triangle in the plane z = h.
  const auto any_hit_at = [&](float h, const Ray& r) {
    const std::vector<std::array<Vec3f, 3>> one = {{Vec3f{-1, -1, h}, Vec3f{3, -1, h}, Vec3f{-1, 3, h}}};
    const TriangleSoup so = soup_of(one);
    const CertifiedIntersector co(so);
    const LeafTriangle lo{one[0][0], one[0][1], one[0][2]};
    REQUIRE(!reference_nearest(so, r, prims).hit());
    NearestHit b;
    detail::exact_leaf_staged<true>(co, r, detail::exact_ray_const(r), prims.data(), &lo, 1, b, nullptr);
    return b.hit.hit();
  };
  // z = 2^30 with d = (0, 0, 2^-100): t = 2^130 > FLT_MAX.
  CHECK(!any_hit_at(0x1p30f, make_ray({0, 0, 0}, {0, 0, 0x1p-100f})));
  // t = (2^25 - 1) 2^103 = FLT_MAX + half an ulp exactly, which rounds to
  // +inf: the enclosure straddles the top of the float range and stays open.
  CHECK(!any_hit_at(0x1p25f, make_ray({0, 0, 1}, {0, 0, 0x1p-103f})));
}

namespace {

/// The certified intersector, counting the calls a traversal's staged test
/// makes to it (each one a triangle the inline stages left open).
class CountingIntersector final : public LeafIntersector {
 public:
  explicit CountingIntersector(const CertifiedIntersector& c) : c_(c) { staged_ = c.staged(); }
  std::string name() const override { return "counting"; }
  void intersect(const Ray& ray, std::span<const std::uint32_t> prims, const LeafTriangle* corners, NearestHit& best,
                 RayCounters* counters) const override {
    ++calls;
    c_.intersect(ray, prims, corners, best, counters);
  }
  mutable int calls = 0;

 private:
  const CertifiedIntersector& c_;
};

/// detail::exact_leaf_staged over one leaf holding `prims` in this order.
NearestHit staged_leaf(const LeafIntersector& x, const TriangleSoup& s, const Ray& r,
                       const std::vector<std::uint32_t>& prims, RayCounters* counters = nullptr) {
  std::vector<LeafTriangle> corners;
  for (const std::uint32_t q : prims) corners.push_back({s.corner(q, 0), s.corner(q, 1), s.corner(q, 2)});
  NearestHit best;
  detail::exact_leaf_staged(x, r, detail::exact_ray_const(r), prims.data(), corners.data(),
                            std::uint32_t(prims.size()), best, counters);
  return best;
}

}  // namespace

// Issue #23: on the teapot with every triangle listed twice (the copy with
// reversed winding), rays aimed at vertices made the staged test call the
// intersector about once a ray (two copies hit inside at the same t), and
// every triangle around a vertex the ray passes through took the full double
// stage and rule (a) to tie at that vertex.
TEST_CASE("staged exact leaf: ties at a vertex the ray passes through, of duplicates and in an axis plane need no "
          "intersector call",
          "[exact][exact-leaf][regression]") {
  // A closed fan around v (dyadic coordinates: v - o is exact for the
  // origins below, so the rays pass exactly through v at t = 1), each
  // triangle followed by its copy with reversed winding.
  const Vec3f v{0.25f, 0.5f, 0.75f};
  std::vector<std::array<Vec3f, 3>> tris;
  std::vector<Vec3f> ring;
  for (int k = 0; k < 6; ++k) {
    const float a = float(k) * 1.0471976f;
    ring.push_back({0.25f + 0.5f * std::cos(a), 0.5f + 0.5f * std::sin(a), 0.75f + 0.125f * std::cos(2 * a + 0.5f)});
  }
  for (int k = 0; k < 6; ++k) {
    tris.push_back({v, ring[k], ring[(k + 1) % 6]});
    tris.push_back({v, ring[(k + 1) % 6], ring[k]});
  }
  const TriangleSoup s = soup_of(tris);
  const CertifiedIntersector c(s);
  const CountingIntersector counting(c);
  std::vector<std::uint32_t> order(s.size());
  for (std::uint32_t i = 0; i < s.size(); ++i) order[i] = i;
  std::mt19937 rng(23);
  std::uniform_int_distribution<int> grid(-8, 8);
  int through = 0;
  for (int i = 0; i < 300; ++i) {
    const Vec3f o{float(grid(rng)), float(grid(rng)), float(grid(rng)) + 0.5f};
    const Ray r = make_ray(o, v - o);
    std::shuffle(order.begin(), order.end(), rng);
    const Hit want = reference_nearest(s, r, order);
    REQUIRE(want.hit());  // a line through v meets each triangle of the fan at v only
    ++through;
    RayCounters counters;
    counting.calls = 0;
    const NearestHit got = staged_leaf(counting, s, r, order, &counters);
    require_same(got.hit, want);
    CHECK(counting.calls == 0);
    // Rule (a) for the first triangle at v, then one tie rule for each of the
    // eleven others (the ray crosses every plane of the fan: the origins lie
    // off all of them), not rule (a) and (b) again for each.
    CHECK(counters.rule_decisions == 12);
    CHECK(counters.exact_decisions == 0);
  }
  CHECK(through == 300);

  // Rays into the inside of a triangle of the fan hit it and its copy at the
  // same t, in a slanted plane: a tie by their corners.
  counting.calls = 0;
  for (int i = 0; i < 300; ++i) {
    const Vec3f o{float(grid(rng)), float(grid(rng)), float(grid(rng)) + 0.5f};
    const auto& t = tris[2 * std::size_t(i % 6)];
    const Ray r = make_ray(o, (t[0] + t[1] + t[2]) * (1.0f / 3.0f) - o);
    std::shuffle(order.begin(), order.end(), rng);
    const Hit want = reference_nearest(s, r, order);
    REQUIRE(want.hit());
    RayCounters counters;
    require_same(staged_leaf(counting, s, r, order, &counters).hit, want);
    CHECK(counters.rule_decisions >= 1);  // a tie of the copies (more where the ray meets an edge)
  }
  CHECK(counting.calls == 0);

  // vertex_tie gives a new nearest hit the fields the stages give it alone.
  for (int i = 0; i < 200; ++i) {
    const Vec3f o{float(grid(rng)), float(grid(rng)), float(grid(rng)) + 0.5f};
    const Ray r = make_ray(o, v - o);
    const detail::ExactRayConst fr = detail::exact_ray_const(r);
    for (std::uint32_t k = 0; k + 1 < s.size(); ++k) {
      const NearestHit alone = staged_leaf(c, s, r, {k});
      NearestHit best = staged_leaf(c, s, r, {std::uint32_t(s.size() - 1)});
      if (!alone.hit.hit() || best.on != 1) continue;
      const auto tri = std::bit_cast<std::array<float, 9>>(s.corners(k));
      REQUIRE(detail::vertex_tie(fr, k, tri, best));
      REQUIRE(best.hit.prim == k);
      REQUIRE(std::bit_cast<std::uint32_t>(best.hit.t) == std::bit_cast<std::uint32_t>(alone.hit.t));
      REQUIRE(std::bit_cast<std::uint32_t>(best.hit.u) == std::bit_cast<std::uint32_t>(alone.hit.u));
      REQUIRE(std::bit_cast<std::uint32_t>(best.hit.v) == std::bit_cast<std::uint32_t>(alone.hit.v));
      REQUIRE(best.tri == alone.tri);
    }
  }

  // A triangle whose plane holds the ray is no tie, though it has a corner at
  // the vertex: the reference does not count such a ray as a hit on it
  // (every Plücker sign is 0). Triangle 0 lies in z = 0.75 with v as a
  // corner; triangle 1 crosses the ray at v.
  {
    const std::vector<std::array<Vec3f, 3>> pair = {{v, Vec3f{-0.75f, 1.0f, 0.75f}, Vec3f{-0.75f, 0.0f, 0.75f}},
                                                    {v, Vec3f{0.25f, 1.5f, 0.0f}, Vec3f{0.25f, -0.5f, 0.0f}}};
    const TriangleSoup t = soup_of(pair);
    const CertifiedIntersector ct(t);
    const Ray r = make_ray({-3.75f, 0.5f, 0.75f}, Vec3f{0.25f, 0.5f, 0.75f} - Vec3f{-3.75f, 0.5f, 0.75f});
    const Hit want = reference_nearest(t, r, {1, 0});
    REQUIRE(want.prim == 1);
    require_same(staged_leaf(ct, t, r, {1, 0}).hit, want);
    NearestHit both;
    ct.intersect(r, std::vector<std::uint32_t>{1, 0}, both, nullptr);
    require_same(both.hit, want);
  }

  // Points in one axis plane z = 0 that the ray does not cross (it lies in
  // it) are no tie: A (1) is hit at its corner (1, 0, 0), t = 1; B (0)
  // touches the ray with an edge in z = 0, at t = 1 + 2^-53 or so, inside the
  // double enclosure of A's t.
  {
    const std::vector<std::array<Vec3f, 3>> ab = {
        {Vec3f{1.0f, -0x1p-30f, 0}, Vec3f{1.0f + 0x1p-23f, 1.0f, 0}, Vec3f{1.5f, 0, 1}},  // B
        {Vec3f{1, 0, 0}, Vec3f{1, 1, 1}, Vec3f{1, -1, 1}}};                               // A
    const TriangleSoup t = soup_of(ab);
    const CertifiedIntersector ct(t);
    const Ray r = make_ray({0, 0, 0}, {1, 0, 0});
    REQUIRE(reference_t(r, t.corners(0)));
    const Hit want = reference_nearest(t, r, {0, 1});
    REQUIRE(want.prim == 1);
    require_same(staged_leaf(ct, t, r, {0, 1}).hit, want);
    require_same(staged_leaf(ct, t, r, {1, 0}).hit, want);
  }

  // Two copies hit inside, and two overlapping triangles in the plane z = c
  // with no corner in common: ties by rule, inline.
  {
    const float z = 595.246f;
    const std::vector<std::array<Vec3f, 3>> quad = {
        {Vec3f{0, 0, z}, Vec3f{0, 1, z}, Vec3f{1, 0, z}},          // 0
        {Vec3f{0, 0, z}, Vec3f{1, 0, z}, Vec3f{0, 1, z}},          // 1: 0 reversed
        {Vec3f{-0.5f, -0.5f, z}, Vec3f{1.5f, -0.25f, z}, Vec3f{-0.25f, 1.5f, z}}};  // 2: overlaps 0 and 1
    const TriangleSoup t = soup_of(quad);
    const CertifiedIntersector ct(t);
    const CountingIntersector cc(ct);
    std::uniform_real_distribution<float> u(0.05f, 0.4f);
    for (int i = 0; i < 200; ++i) {
      const Ray r = make_ray({u(rng), u(rng), 0.0f}, {1e-4f * u(rng), 2e-4f * u(rng), 1.0f});
      const Hit want = reference_nearest(t, r, {2, 1, 0});
      REQUIRE(want.prim == 0);
      RayCounters counters;
      require_same(staged_leaf(cc, t, r, {2, 1, 0}, &counters).hit, want);
      CHECK(counters.rule_decisions == 2);
    }
    CHECK(cc.calls == 0);
  }
}

}  // namespace bsprt
