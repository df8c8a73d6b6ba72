/// \file epsilon_bound.cpp
/// Interval bounds of the float-plane rounding (epsilon_bound.h), with
/// CGAL::Interval_nt<false> under the caller's RoundingGuard.
#include "robust/epsilon_bound.h"

#include <CGAL/Interval_nt.h>

#include <cmath>
#include <limits>

namespace bsprt {

namespace {
using IA = CGAL::Interval_nt<false>;

/// Smallest float >= x (x finite, >= 0).
float float_up(double x) {
  float f = static_cast<float>(x);
  while (double(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}
}  // namespace

double plane_rounding_bound(const RoundingGuard&, const PreparedPlane& plane, double s,
                            const std::array<float, 3>& n, float d,
                            std::span<const IntervalBox> vertices) {
  // Near the float range's end the offset d or a vertex enclosure overflows:
  // no bound (+inf), which the flattening reports. CGAL's Interval_nt asserts
  // on an infinite endpoint (found by the sanitizer run of CI, 2026-12-07).
  constexpr double kNoBound = std::numeric_limits<double>::infinity();
  if (!std::isfinite(d) || !std::isfinite(s)) return kNoBound;
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(n[i]) || !std::isfinite(plane.n_lo[i]) || !std::isfinite(plane.n_hi[i]) ||
        !std::isfinite(plane.ref[i]))
      return kNoBound;
  for (const IntervalBox& v : vertices)
    for (int i = 0; i < 3; ++i)
      if (!std::isfinite(v.lo[i]) || !std::isfinite(v.hi[i])) return kNoBound;
  IA c[3];
  IA kappa(double{d});
  for (int i = 0; i < 3; ++i) {
    c[i] = IA(double{n[i]}) - IA(s) * IA(plane.n_lo[i], plane.n_hi[i]);
    kappa += IA(double{n[i]}) * IA(plane.ref[i]);
  }
  double delta = 0.0;
  for (const IntervalBox& v : vertices) {
    IA sum = kappa;
    for (int i = 0; i < 3; ++i) sum += c[i] * (IA(v.lo[i], v.hi[i]) - IA(plane.ref[i]));
    const double bound = CGAL::abs(sum).sup();
    if (!(bound <= delta)) delta = bound;  // NaN propagates as "no bound"
  }
  return delta;
}

FloatPlane float_plane_bound(const RoundingGuard& g, const PreparedPlane& plane,
                             std::span<const IntervalBox> vertices) {
  FloatPlane f;
  double mid[3], len2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    mid[i] = 0.5 * (plane.n_lo[i] + plane.n_hi[i]);
    len2 += mid[i] * mid[i];
  }
  f.scale = 1.0 / std::sqrt(len2);
  double dd = 0.0;
  for (int i = 0; i < 3; ++i) {
    f.n[i] = static_cast<float>(mid[i] * f.scale);
    dd -= double{f.n[i]} * plane.ref[i];
  }
  f.d = static_cast<float>(dd);
  f.delta = plane_rounding_bound(g, plane, f.scale, f.n, f.d, vertices);
  f.eps = node_epsilon(f.delta, f.d);
  return f;
}

float node_epsilon(double delta, float d) {
  if (!std::isfinite(delta)) return std::numeric_limits<float>::infinity();
  double e = delta + 0x1p-23 * std::fabs(double{d});
  e = std::nextafter(e * (1.0 + 0x1p-20), std::numeric_limits<double>::infinity());
  return float_up(e);
}

}  // namespace bsprt
