/// \file exact_eval.cpp
/// The exact stage of the side tests (exact_side.h): plane coefficients and
/// triple-plane intersections evaluated with CGAL::Mpzf, which adds and
/// multiplies doubles exactly. Every value is a polynomial in the input floats
/// (no division: the intersection point N/D is tested as sign(n·N + d·D)·sign(D)).
#include <CGAL/FPU.h>
#include <CGAL/Gmpq.h>
#include <CGAL/Interval_nt.h>
#include <CGAL/Mpzf.h>

#include <cmath>
#include <utility>

#include "geometry/core/check.h"
#include "robust/exact_side.h"
#include "robust/plane_formula.h"

namespace bsprt {

namespace {

using NT = CGAL::Mpzf;
using V3 = Vec3<NT>;  // cross and dot: bsprt/vec3.h, written once over the number type

V3 to_v3(const Vec3f& p) { return {NT(double(p.x)), NT(double(p.y)), NT(double(p.z))}; }

/// Exact normal n and offset d (value = n·p + d) of a stored plane.
struct ExactPlane {
  V3 n;
  NT d;
};

ExactPlane exact_plane(const TriangleSoup& soup, PlaneDef p) {
  const PlaneFormula<NT> f = plane_formula<NT>(soup, p);
  return {f.n, p.is_kd() ? NT(-double(p.coord())) : -dot(f.n, to_v3(f.through))};
}

/// Homogeneous intersection (N, D) of three planes: the point is N / D.
struct Homogeneous {
  V3 num;
  NT den;
};

Homogeneous intersect(const TriangleSoup& soup, const std::array<PlaneDef, 3>& def) {
  const ExactPlane a = exact_plane(soup, def[0]), b = exact_plane(soup, def[1]),
                   c = exact_plane(soup, def[2]);
  const V3 bc = cross(b.n, c.n), ca = cross(c.n, a.n), ab = cross(a.n, b.n);
  Homogeneous h;
  h.den = dot(a.n, bc);
  BSPRT_CHECK(!h.den.is_zero());  // three stored planes that do not meet in a point
  const V3 s1 = bc * a.d, s2 = ca * b.d, s3 = ab * c.d;
  for (int i = 0; i < 3; ++i) h.num[i] = -(s1[i] + s2[i] + s3[i]);
  return h;
}

int sign_of(const NT& x) { return x.is_zero() ? 0 : (x.sign() > 0 ? 1 : -1); }

}  // namespace

int exact_side_at(const TriangleSoup& soup, PlaneDef plane, const std::array<double, 3>& p) {
  const ExactPlane e = exact_plane(soup, plane);
  const NT v = e.n[0] * NT(p[0]) + e.n[1] * NT(p[1]) + e.n[2] * NT(p[2]) + e.d;
  return sign_of(v);
}

int exact_side_at(const TriangleSoup& soup, PlaneDef plane, const std::array<PlaneDef, 3>& def) {
  const Homogeneous h = intersect(soup, def);
  const ExactPlane e = exact_plane(soup, plane);
  const NT v = dot(e.n, h.num) + e.d * h.den;
  return sign_of(v) * sign_of(h.den);
}

/// Whether Mpzf::to_interval is trusted for x: zero, or |x| in [2^-960, 2^960].
/// CGAL 5.5's Mpzf::to_interval is not sound below the double range when the
/// rounding mode is upward, as it is here (RoundingGuard): it scales by
/// std::ldexp(1.0, e), which then rounds 2^-1216 up to the smallest subnormal
/// instead of to 0, and CGAL takes that as an exact scale: Mpzf(2^-600) *
/// Mpzf(2^-578) = 2^-1178 becomes the point [2^-1036, 2^-1036] (in
/// round-to-nearest, the true [0, 2^-1036]). A cell vertex of a scene with coordinates near
/// 2^-138 was placed 2^128 times too far out, and the build ended in an
/// internal error (a differential review of 2026-12-07; regression test "bsp
/// build: a scene with subnormal coordinates builds, verifies and traces
/// exactly", tests/test_regressions.cpp). The verifier's intervals are of
/// plane coefficients, at most degree 4 in the floats, so never below 2^-596.
bool interval_trusted(const NT& x) {
  if (x.is_zero()) return true;
  const NT a = CGAL::abs(x);
  return a >= NT(0x1p-960) && a <= NT(0x1p960);
}

IntervalBox exact_enclosure(const TriangleSoup& soup, const std::array<PlaneDef, 3>& def) {
  const Homogeneous h = intersect(soup, def);
  using IA = CGAL::Interval_nt<true>;  // self-protecting: callable in any rounding mode
  const IA den(h.den.to_interval());
  IntervalBox box;
  for (int i = 0; i < 3; ++i) {
    std::pair<double, double> x;
    if (interval_trusted(h.den) && interval_trusted(h.num[i])) {
      const IA q = IA(h.num[i].to_interval()) / den;
      x = {q.inf(), q.sup()};
    } else {
      // The coordinate itself is in range (a vertex of a cell of float
      // planes): take the quotient exactly and let MPFR round it outward.
      x = CGAL::to_interval(CGAL::Gmpq(h.num[i]) / CGAL::Gmpq(h.den));
    }
    box.lo[i] = x.first;
    box.hi[i] = x.second;
  }
  return box;
}

bool triangle_degenerate_exact(const TriangleSoup& soup, std::uint32_t t) {
  for (int k = 0; k < 3; ++k)
    if (!is_finite(soup.corner(t, k))) return true;
  const V3 p0 = to_v3(soup.corner(t, 0)), p1 = to_v3(soup.corner(t, 1)), p2 = to_v3(soup.corner(t, 2));
  const V3 n = cross(p1 - p0, p2 - p0);
  return n[0].is_zero() && n[1].is_zero() && n[2].is_zero();
}

RoundingGuard::RoundingGuard() : saved_(static_cast<unsigned>(CGAL::FPU_get_cw())) {
  CGAL::FPU_set_cw(CGAL_FE_UPWARD);
}
RoundingGuard::~RoundingGuard() { CGAL::FPU_set_cw(static_cast<CGAL::FPU_CW_t>(saved_)); }

}  // namespace bsprt
