#include "robust/certified_intersector.h"
#include "robust/exact_sum.h"

#include <CGAL/Mpzf.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>

#include "traverse/exact_double_stage.h"

namespace bsprt {
namespace {

/// The exact stage's number type: a heap-free big float for the small
/// magnitudes of float data (CGAL keeps 8 limbs inline; products of floats
/// that span more than 512 bits of exponent are the only ones that allocate).
using Mp = CGAL::Mpzf;

constexpr float kInf = std::numeric_limits<float>::infinity();

using detail::ExactRayConst;
using detail::Stage;

struct M3 {
  Mp x, y, z;
};
M3 msub(const Vec3f& a, const Vec3f& b) {
  return {Mp(double(a.x)) - Mp(double(b.x)), Mp(double(a.y)) - Mp(double(b.y)), Mp(double(a.z)) - Mp(double(b.z))};
}
M3 mvec(const Vec3f& a) { return {Mp(double(a.x)), Mp(double(a.y)), Mp(double(a.z))}; }
Mp mdot(const M3& a, const M3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
M3 mcross(const M3& a, const M3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
int msign(const Mp& x) { return int(x.sign()); }

/// t = num / den exactly, den > 0 (the face-normal form n.(v0 - o) / n.d).
struct ExactT {
  Mp num, den;
};
ExactT exact_t(const Ray& ray, const std::array<Vec3f, 3>& tri) {
  const M3 n = mcross(msub(tri[1], tri[0]), msub(tri[2], tri[0]));
  ExactT e{mdot(n, msub(tri[0], ray.org)), mdot(n, mvec(ray.dir))};
  if (msign(e.den) < 0) e.num = -e.num, e.den = -e.den;
  return e;
}
/// sign(t - m) for a double m.
int compare_t(const ExactT& e, double m) { return msign(e.num - Mp(m) * e.den); }

/// The float nearest to the exact t (ties to even), with the enclosure
/// [lo, hi] between the two midpoints around it; +inf when t rounds to
/// infinity. No division: each step compares t with a midpoint of floats,
/// which is a double.
float round_exact(const ExactT& e, double& lo, double& hi) {
  constexpr double kOverflow = 0x1.ffffffp127;  // FLT_MAX + half an ulp: ties to even go up to infinity
  if (compare_t(e, kOverflow) >= 0) return kInf;
  if (compare_t(e, -kOverflow) <= 0) return -kInf;
  float f = float(e.num.to_double() / e.den.to_double());
  if (!std::isfinite(f)) f = std::copysign(std::numeric_limits<float>::max(), f);
  for (;;) {
    const float down = std::nextafter(f, -kInf), up = std::nextafter(f, kInf);
    const double m_lo = std::isfinite(down) ? (double(f) + double(down)) / 2 : -kOverflow;
    const double m_hi = std::isfinite(up) ? (double(f) + double(up)) / 2 : kOverflow;
    const int below = compare_t(e, m_lo), above = compare_t(e, m_hi);
    if (below < 0) {
      f = down;
      continue;
    }
    if (above > 0) {
      f = up;
      continue;
    }
    lo = m_lo, hi = m_hi;
    const auto odd = [](float x) { return (std::bit_cast<std::uint32_t>(x) & 1u) != 0; };
    if (below == 0 && odd(f)) return down;  // ties to even
    if (above == 0 && odd(f)) return up;
    return f;
  }
}

/// A hit of one triangle: the float t, an enclosure [t_lo, t_hi] of the
/// exact t, the barycentrics and where on the triangle it lies.
struct Candidate {
  double t_lo, t_hi;
  float t, u, v;
  std::uint8_t on = 0;  ///< NearestHit::on
  Vec3f p, q;
  int sign = 0;  ///< the weights' common sign: +1 or -1 (which side the ray comes from)
};

/// Decision counts of one call, added to the counters once.
struct Stages {
  std::uint64_t rule = 0, exact = 0;
};

/// Simulation of simplicity for a weight that is exactly 0: its sign when the
/// origin moves to o + (e, e^2, e^3) for an infinitesimal e > 0. The weight
/// pairing p and q (in this order) becomes w - delta.((q - p) x d), so its sign
/// is minus the sign of the first non-zero component of (q - p) x d; 0 when q - p
/// is parallel to d (the ray is then parallel to the triangle's plane). Each
/// component is a sum of four products of floats (cross_terms), signed
/// exactly without the heap (exact_sum.h).
int sos_sign(const Vec3f& p, const Vec3f& q, const Vec3f& dir) {
  for (int j = 0; j < 3; ++j) {
    double approx;
    if (const int s = detail::exact_sum_sign(detail::cross_terms(q, p, dir, j), approx); s != 0) return -s;
  }
  return 0;
}

/// Decides one triangle; nullopt = no hit with t in [tnear, tfar]. With
/// `sos`, a crossing of the perturbed ray instead (sos_sign): exact zeros
/// take their perturbed signs, so a ray through a shared edge or vertex of a
/// closed, consistently oriented mesh crosses exactly one triangle of each sheet.
std::optional<Candidate> test_one(const Ray& ray, const ExactRayConst& fr, const std::array<Vec3f, 3>& tri, Stages& st,
                                  bool sos = false) {
  // Double stage (exact_double_stage.h): the weights of v0, v1, v2 as
  // sheared 2D cross products, each with its static bound.
  const std::array<float, 9> floats{tri[0].x, tri[0].y, tri[0].z, tri[1].x, tri[1].y,
                                    tri[1].z, tri[2].x, tri[2].y, tri[2].z};
  detail::StageWeights sw;
  if (detail::double_weights(fr, floats, sw) == Stage::Miss) return std::nullopt;  // whatever the third weight is
  double* const w = sw.w;
  int* const s = sw.s;
  if (exact_filter_off_for_testing != 0) {
    for (int k = 0; k < 3; ++k)
      if ((exact_filter_off_for_testing >> k) & 1u) s[k] = 2;
  }
  if (s[0] == 2 || s[1] == 2 || s[2] == 2) {
    // Rule (a): a vertex exactly on the ray's line through o + d or o - d.
    bool rule = detail::vertex_rule(fr, ray, floats, sw);
    // A filter on the volumes from the edges (exact_sum.h), tighter than the
    // double stage's for a small triangle far from the origin; it and the two
    // rules after it stay off while a test forces volumes to the exact stage.
    const bool more = exact_filter_off_for_testing == 0;
    for (int k = 0; k < 3 && more; ++k) {
      if (s[k] != 2) continue;
      double vol, bound;
      const int sign = detail::edge_volume_filter(tri[(k + 1) % 3], tri[(k + 2) % 3], ray.org, ray.dir, vol, bound);
      if (sign == 2) continue;
      s[k] = sign, w[k] = vol / fr.abs_d;  // on the sheared scale, for u and v
    }
    // Rule (a) for a vertex anywhere on the ray's line, checked exactly
    // (exact_sum.h): the two volumes that pair it with the other corners are
    // 0. Such a corner has both volumes open, or already 0 (a ray along an
    // edge has two corners on its line).
    for (int i = 0; i < 3 && more; ++i) {
      const int k1 = i == 0 ? 1 : 0, k2 = i == 2 ? 1 : 2;  // the volumes that pair corner i
      const bool zero_or_open = (s[k1] == 2 || s[k1] == 0) && (s[k2] == 2 || s[k2] == 0);
      if (!zero_or_open || (s[k1] != 2 && s[k2] != 2) || !detail::on_line_exactly(tri[i], ray.org, ray.dir)) continue;
      s[k1] = s[k2] = 0, w[k1] = w[k2] = 0.0;
      rule = true;
    }
    // Rule (c): a volume of an axis-parallel edge, exactly without the exact
    // stage (exact_sum.h): the exact zeros of rays through the edges of
    // architectural models.
    for (int k = 0; k < 3 && more; ++k) {
      if (s[k] != 2) continue;
      double approx;
      if (!detail::axis_edge_volume_sign(tri[(k + 1) % 3], tri[(k + 2) % 3], ray.org, ray.dir, s[k], approx)) continue;
      w[k] = s[k] == 0 ? 0.0 : approx / fr.abs_d;  // on the sheared scale, for u and v
      rule = true;
    }
    if (s[0] == 2 || s[1] == 2 || s[2] == 2) {  // exact stage for what is still open
      ++st.exact;
      const M3 e0 = msub(tri[0], ray.org), e1 = msub(tri[1], ray.org), e2 = msub(tri[2], ray.org), ed = mvec(ray.dir);
      const M3* e[3] = {&e0, &e1, &e2};
      for (int k = 0; k < 3; ++k) {
        if (s[k] != 2) continue;
        const Mp x = mdot(mcross(*e[(k + 1) % 3], *e[(k + 2) % 3]), ed);  // the Plücker volume
        s[k] = msign(x);
        w[k] = s[k] == 0 ? 0.0 : x.to_double() / fr.abs_d;  // on the sheared scale, for u and v
      }
    } else if (rule) {
      ++st.rule;
    }
  }
  if (sos && (s[0] == 0 || s[1] == 0 || s[2] == 0)) {
    if (s[0] == 0 && s[1] == 0 && s[2] == 0) return std::nullopt;  // the ray lies in the plane
    ++st.rule;  // exact signs of float products, no exact stage
    for (int k = 0; k < 3; ++k)
      if (s[k] == 0) s[k] = sos_sign(tri[(k + 1) % 3], tri[(k + 2) % 3], ray.dir);
  }
  if (!detail::meets(sw.s)) return std::nullopt;

  Candidate c;
  c.sign = (s[0] > 0 || s[1] > 0 || s[2] > 0) ? 1 : -1;
  detail::hit_place(sw.s, floats, c.on, c.p, c.q);
  detail::stage_barycentrics(sw.w, c.u, c.v);

  // t in double with its static bound (exact_double_stage.h), else exactly.
  const Stage ts = detail::double_t(fr, ray, floats, c.t, c.t_lo, c.t_hi);
  if (ts == Stage::Miss) return std::nullopt;
  if (ts == Stage::Open) {
    ++st.exact;
    const ExactT e = exact_t(ray, tri);
    const double tnear = ray.tnear, tfar = ray.tfar;
    // An infinite bound on the wrong side ([+inf, +inf], [-inf, -inf]) admits no finite t.
    if (tnear == std::numeric_limits<double>::infinity() || tfar == -std::numeric_limits<double>::infinity())
      return std::nullopt;
    if (std::isfinite(tnear) && compare_t(e, tnear) < 0) return std::nullopt;
    if (std::isfinite(tfar) && compare_t(e, tfar) > 0) return std::nullopt;
    c.t = round_exact(e, c.t_lo, c.t_hi);
    if (std::isinf(c.t)) return std::nullopt;
  }
  return c;
}

/// Whether two hits lie in one plane parallel to a coordinate axis k, which
/// the ray crosses: projected along k (coordinates u, v), the points each hit
/// is known to lie among (detail::known_points) lie on one line L through two
/// of them, a and b, and the ray's direction is not parallel to L. Both hits
/// then lie on the plane L x axis k, which the ray meets in one point, so
/// their exact t's are equal. Each test is the exact sign of a sum of
/// products of floats (exact_sum.h). Vertical walls and what hangs on them
/// (conference's slanted walls) are the planes parallel to one axis. The
/// axis-aligned plane x_k = c, the common case (a panel on a ceiling, a rug
/// on a floor: 97 of the 98 exact decisions on 90K conference camera rays,
/// kd, were such ties), needs float comparisons only and is checked first,
/// by detail::same_t_by_corners.
bool same_plane_along_axis(const Candidate& c, const std::array<float, 9>& tri, const NearestHit& best,
                           const Ray& ray) {
  Vec3f pt[6];
  Vec3f a3[3], b3[3];
  const int na = detail::known_points(c.on, c.p, c.q, tri, a3);
  const int nb = detail::known_points(best.on, best.p, best.q, best.tri, b3);
  int n = 0;
  for (int i = 0; i < na; ++i) pt[n++] = a3[i];
  for (int i = 0; i < nb; ++i) pt[n++] = b3[i];
  const Vec3f& d = ray.dir;
  for (int k = 0; k < 3; ++k) {  // a plane containing axis k
    const int u = (k + 1) % 3, v = (k + 2) % 3;
    const Vec3f& a = pt[0];
    int ib = -1;
    for (int i = 1; i < n && ib < 0; ++i)
      if (pt[i][u] != a[u] || pt[i][v] != a[v]) ib = i;
    if (ib < 0) continue;
    const Vec3f& b = pt[ib];
    const auto f = [](float x, float y) { return double(x) * double(y); };
    double approx;
    // ((b - a) x d)[k]: the projected direction is not parallel to L
    if (detail::exact_sum_sign(detail::cross_terms(b, a, d, k), approx) == 0) continue;
    bool on_line = true;
    for (int i = 1; i < n && on_line; ++i) {
      if (i == ib) continue;
      const Vec3f& p = pt[i];  // (b - a) x (p - a), projected, with a[u] a[v] cancelled
      on_line = detail::exact_sum_sign(std::array<double, 6>{f(b[u], p[v]), -f(b[u], a[v]), -f(a[u], p[v]),
                                                             -f(b[v], p[u]), f(b[v], a[u]), f(a[v], p[u])},
                                       approx) == 0;
    }
    if (on_line) return true;
  }
  return false;
}

/// Whether two hits have the same exact t for a reason that needs no
/// arithmetic beyond exact signs of sums of float products: the same vertex,
/// the same edge, triangles with the same corners, or hits in one plane
/// parallel to a coordinate axis that the ray crosses. The first checks are
/// the staged test's own (detail::same_t_by_corners).
bool same_t_by_rule(const Candidate& c, const std::array<float, 9>& tri, const NearestHit& best, const Ray& ray) {
  return detail::same_t_by_corners(c.on, c.p, c.q, tri, best, ray) || same_plane_along_axis(c, tri, best, ray);
}

}  // namespace

CertifiedIntersector::CertifiedIntersector(const TriangleSoup& soup) : soup_(soup) {
  staged_ = true;  // test_one runs exact_double_stage.h's functions first
}

void CertifiedIntersector::set_filter_off_for_testing(unsigned weights) { exact_filter_off_for_testing = weights & 7u; }

void CertifiedIntersector::intersect(const Ray& ray, std::span<const std::uint32_t> prims,
                                     const LeafTriangle* corners, NearestHit& best, RayCounters* counters) const {
  if (!is_valid(ray)) return;
  const ExactRayConst fr = detail::exact_ray_const(ray);
  Stages st;
  for (std::size_t i = 0; i < prims.size(); ++i) {
    const std::uint32_t prim = prims[i];
    if (counters) ++counters->triangle_tests;
    // The nearest triangle so far, met again in another leaf (a triangle is
    // listed in every leaf it touches): test_one is a function of the ray and
    // the triangle alone, so it would return the same candidate, which is not
    // nearer than itself.
    if (best.hit.hit() && prim == best.hit.prim) continue;
    // Degenerate triangles (collinear or non-finite corners) never hit; a
    // non-finite corner must not reach the exact stage (Mpzf takes finite doubles).
    if (soup_.is_degenerate(prim)) continue;
    const std::array<Vec3f, 3> tri =
        corners ? std::array<Vec3f, 3>{corners[i].v[0], corners[i].v[1], corners[i].v[2]} : soup_.corners(prim);
    const auto tri9 = std::bit_cast<std::array<float, 9>>(tri);
    if (detail::vertex_tie(fr, prim, tri9, best)) {
      ++st.rule;
      continue;
    }
    const std::optional<Candidate> c = test_one(ray, fr, tri, st);
    if (!c) continue;
    bool nearer;
    if (!best.hit.hit() || c->t_hi < best.t_lo) {
      nearer = true;
    } else if (c->t_lo > best.t_hi) {
      nearer = false;
    } else {  // enclosures overlap
      const auto best_tri = std::bit_cast<std::array<Vec3f, 3>>(best.tri);
      int order;  // sign(t - best t)
      if (same_t_by_rule(*c, tri9, best, ray)) {
        ++st.rule;
        order = 0;
      } else {
        ++st.exact;
        const ExactT mine = exact_t(ray, tri), theirs = exact_t(ray, best_tri);
        order = msign(mine.num * theirs.den - theirs.num * mine.den);
      }
      nearer = order < 0 || (order == 0 && prim < best.hit.prim);
    }
    if (!nearer) continue;
    best.hit = Hit{c->t + 0.0f, prim, c->u, c->v};  // + 0: a zero t is +0 (docs/exact-leaf-test.md, "Hits beyond the float range")
    best.t_lo = c->t_lo;
    best.t_hi = c->t_hi;
    best.on = c->on;
    best.p = c->p;
    best.q = c->q;
    best.tri = tri9;
  }
  if (st.exact) fallbacks_.fetch_add(st.exact, std::memory_order_relaxed);
  if (counters) {
    counters->rule_decisions += st.rule;
    counters->exact_decisions += st.exact;
  }
}

void CertifiedIntersector::crossings(const Ray& ray, std::span<const std::uint32_t> prims, std::vector<Crossing>& out,
                                     RayCounters* counters) const {
  if (!is_valid(ray)) return;
  const ExactRayConst fr = detail::exact_ray_const(ray);
  Stages st;
  for (const std::uint32_t prim : prims) {
    if (counters) ++counters->triangle_tests;
    if (soup_.is_degenerate(prim)) continue;  // never crossed (and never handed to Mpzf)
    const std::array<Vec3f, 3> tri = soup_.corners(prim);
    const std::optional<Candidate> c = test_one(ray, fr, tri, st, true);
    if (!c) continue;
    out.push_back({prim, c->t + 0.0f, c->sign});  // a zero t is +0, as in intersect (review of 2026-12-07)
  }
  if (st.exact) fallbacks_.fetch_add(st.exact, std::memory_order_relaxed);
  if (counters) {
    counters->rule_decisions += st.rule;
    counters->exact_decisions += st.exact;
  }
}

CertifiedBruteTracer::CertifiedBruteTracer(const TriangleSoup& soup) : soup_(soup), intersector_(soup) {
  for (std::uint32_t t = 0; t < soup.size(); ++t)
    if (!soup.is_degenerate(t)) live_.push_back(t);
}

Hit CertifiedBruteTracer::trace(const Ray& ray, RayCounters* counters) const {
  NearestHit best;
  if (!counters) {
    intersector_.intersect(ray, live_, best, nullptr);
    return best.hit;
  }
  ++counters->rays;
  const std::uint64_t before = counters->exact_decisions;
  intersector_.intersect(ray, live_, best, counters);
  counters->exact_rays += counters->exact_decisions != before;
  return best.hit;
}

}  // namespace bsprt
