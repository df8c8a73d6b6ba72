#include "robust/certified_intersector.h"

#include <CGAL/Exact_rational.h>
#include <CGAL/Interval_nt.h>

#include <array>
#include <cmath>
#include <optional>

#include "robust/nearest_float.h"

namespace bsprt {
namespace {

using Interval = CGAL::Interval_nt<false>;  // needs upward rounding: Protect_FPU_rounding
using Rational = CGAL::Exact_rational;

/// The Plücker volumes and the t fraction of one ray/triangle pair, in NT.
template <typename NT>
struct Volumes {
  NT u, v, w;  ///< weights of v0, v1, v2 (one sign on a hit)
  NT num, den; ///< t = num / den
};

template <typename NT>
using V3 = std::array<NT, 3>;

template <typename NT>
V3<NT> lift(const Vec3f& p) { return {NT(double(p.x)), NT(double(p.y)), NT(double(p.z))}; }
template <typename NT>
V3<NT> sub(const V3<NT>& a, const V3<NT>& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
template <typename NT>
NT dot(const V3<NT>& a, const V3<NT>& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
template <typename NT>
NT triple(const V3<NT>& a, const V3<NT>& b, const V3<NT>& d) {  // (a x b) . d
  return (a[1] * b[2] - a[2] * b[1]) * d[0] + (a[2] * b[0] - a[0] * b[2]) * d[1] + (a[0] * b[1] - a[1] * b[0]) * d[2];
}

template <typename NT>
Volumes<NT> volumes(const Ray& ray, const std::array<Vec3f, 3>& tri) {
  const V3<NT> o = lift<NT>(ray.org), d = lift<NT>(ray.dir);
  const V3<NT> a0 = sub(lift<NT>(tri[0]), o), a1 = sub(lift<NT>(tri[1]), o), a2 = sub(lift<NT>(tri[2]), o);
  Volumes<NT> r{triple(a1, a2, d), triple(a2, a0, d), triple(a0, a1, d), NT(0), NT(0)};
  r.num = r.u * dot(a0, d) + r.v * dot(a1, d) + r.w * dot(a2, d);
  r.den = (r.u + r.v + r.w) * dot(d, d);
  return r;
}

/// -1, 0, +1, or nullopt when the interval straddles zero.
std::optional<int> sign_of(const Interval& x) {
  if (x.inf() > 0) return 1;
  if (x.sup() < 0) return -1;
  if (x.inf() == 0 && x.sup() == 0) return 0;
  return std::nullopt;
}

/// One sign for all three volumes, not all zero: the line meets the triangle.
bool meets(int su, int sv, int sw) {
  const bool neg = su < 0 || sv < 0 || sw < 0, pos = su > 0 || sv > 0 || sw > 0;
  return !(neg && pos) && (neg || pos);
}

/// A hit of one triangle: t as an enclosure (a point when exact), and the
/// exact value when it had to be computed.
struct Candidate {
  double t_lo, t_hi;
  std::optional<Rational> t_exact;
  float t, u, v;
};

Rational exact_t(const Ray& ray, const std::array<Vec3f, 3>& tri) {
  const Volumes<Rational> e = volumes<Rational>(ray, tri);
  return e.num / e.den;
}

}  // namespace

CertifiedIntersector::CertifiedIntersector(const TriangleSoup& soup) : soup_(soup) {}

namespace {

/// Decides one triangle; nullopt = no hit in [tnear, tfar]. Counts fallbacks.
std::optional<Candidate> test_one(const Ray& ray, const std::array<Vec3f, 3>& tri, std::atomic<std::uint64_t>& fallbacks) {
  std::optional<int> su, sv, sw;
  double lo = 0, hi = 0, u = 0, v = 0;
  {
    CGAL::Protect_FPU_rounding<true> upward;
    const Volumes<Interval> f = volumes<Interval>(ray, tri);
    su = sign_of(f.u), sv = sign_of(f.v), sw = sign_of(f.w);
    if (su && sv && sw && meets(*su, *sv, *sw)) {
      const Interval t = f.num / f.den, sum = f.u + f.v + f.w;
      lo = t.inf(), hi = t.sup();
      u = CGAL::to_double(f.v / sum), v = CGAL::to_double(f.w / sum);
    }
  }
  std::optional<Rational> t_exact;
  if (!su || !sv || !sw) {  // the filter failed: decide exactly
    fallbacks.fetch_add(1, std::memory_order_relaxed);
    const Volumes<Rational> e = volumes<Rational>(ray, tri);
    if (!meets(CGAL::sign(e.u), CGAL::sign(e.v), CGAL::sign(e.w))) return std::nullopt;
    t_exact = e.num / e.den;
    const Rational sum = e.u + e.v + e.w;
    // to_double truncates: one double step each way encloses the exact t.
    const double d = CGAL::to_double(*t_exact);
    lo = std::nextafter(d, -INFINITY), hi = std::nextafter(d, INFINITY);
    u = CGAL::to_double(e.v / sum), v = CGAL::to_double(e.w / sum);
  } else if (!meets(*su, *sv, *sw)) {
    return std::nullopt;
  }
  // t in [tnear, tfar], exactly.
  const double tnear = ray.tnear, tfar = ray.tfar;
  if (!t_exact && ((lo < tnear && hi >= tnear) || (lo <= tfar && hi > tfar))) {
    fallbacks.fetch_add(1, std::memory_order_relaxed);
    t_exact = exact_t(ray, tri);
  }
  if (t_exact) {
    if (*t_exact < Rational(tnear) || (std::isfinite(tfar) && *t_exact > Rational(tfar))) return std::nullopt;
    const float t = nearest_float(*t_exact);
    return Candidate{lo, hi, t_exact, t, float(u), float(v)};
  }
  if (hi < tnear || lo > tfar) return std::nullopt;
  // The float t: both ends round to the same float, else ask the exact value.
  if (float(lo) != float(hi)) {
    t_exact = exact_t(ray, tri);
    return Candidate{lo, hi, t_exact, nearest_float(*t_exact), float(u), float(v)};
  }
  return Candidate{lo, hi, std::nullopt, float(lo), float(u), float(v)};
}

}  // namespace

void CertifiedIntersector::intersect(const Ray& ray, std::span<const std::uint32_t> prims, NearestHit& best,
                                     RayCounters* counters) const {
  if (!is_valid(ray)) return;
  for (const std::uint32_t prim : prims) {
    if (counters) ++counters->triangle_tests;
    // The nearest triangle so far, met again in another leaf (a triangle is
    // listed in every leaf it touches): test_one is a function of the ray and
    // the triangle alone, so it would return the same candidate, which is not
    // nearer than itself. Without this, the equal enclosures would send every
    // such repeat to the exact comparison below (two rational t's).
    if (best.hit.hit() && prim == best.hit.prim) continue;
    const auto tri = soup_.corners(prim);
    std::optional<Candidate> c = test_one(ray, tri, fallbacks_);
    if (!c) continue;
    bool nearer;
    if (!best.hit.hit() || c->t_hi < best.t_lo) {
      nearer = true;
    } else if (c->t_lo > best.t_hi) {
      nearer = false;
    } else {  // enclosures overlap: compare the exact values
      fallbacks_.fetch_add(1, std::memory_order_relaxed);
      const Rational mine = c->t_exact ? *c->t_exact : exact_t(ray, tri);
      const Rational theirs = exact_t(ray, soup_.corners(best.hit.prim));
      nearer = mine < theirs || (mine == theirs && prim < best.hit.prim);
    }
    if (!nearer) continue;
    best.hit = Hit{c->t, prim, c->u, c->v};
    best.t_lo = c->t_lo;
    best.t_hi = c->t_hi;
  }
}

CertifiedBruteTracer::CertifiedBruteTracer(const TriangleSoup& soup) : soup_(soup), intersector_(soup) {
  for (std::uint32_t t = 0; t < soup.size(); ++t)
    if (!soup.is_degenerate(t)) live_.push_back(t);
}

Hit CertifiedBruteTracer::trace(const Ray& ray, RayCounters* counters) const {
  if (counters) ++counters->rays;
  NearestHit best;
  intersector_.intersect(ray, live_, best, counters);
  return best.hit;
}

}  // namespace bsprt
