#include "bsprt/compare.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "bsprt/error.h"

namespace bsprt {

double ulp_distance(float a, float b) {
  if (a == b) return 0.0;
  if (!std::isfinite(a) || !std::isfinite(b)) return INFINITY;
  // Map floats to a monotone integer line, so the difference counts ulps.
  auto key = [](float f) {
    const std::int64_t i = std::bit_cast<std::int32_t>(f);
    return i < 0 ? std::int64_t(INT32_MIN) - i : i;
  };
  return double(std::llabs(key(a) - key(b)));
}

HitComparison compare_hits(std::span<const Hit> reference, std::span<const Hit> tested, double rel_tol) {
  if (reference.size() != tested.size())
    throw UsageError("hit files differ in size: " + std::to_string(reference.size()) + " vs " +
                     std::to_string(tested.size()) + " rays");
  HitComparison c;
  c.rays = reference.size();
  for (std::size_t i = 0; i < reference.size(); ++i) {
    const Hit& r = reference[i];
    const Hit& t = tested[i];
    bool bad = false;
    if (!r.hit() && !t.hit()) {
      ++c.both_miss;
    } else if (r.hit() && !t.hit()) {
      ++c.lost, bad = true;
    } else if (!r.hit() && t.hit()) {
      ++c.extra, bad = true;
    } else {
      c.max_t_ulps = std::max(c.max_t_ulps, ulp_distance(r.t, t.t));
      const double tol = rel_tol * std::max(std::abs(double(r.t)), 1e-30);
      if (r.prim == t.prim) ++c.same_triangle;
      else if (std::abs(double(t.t) - double(r.t)) <= tol) ++c.tie;
      else if (t.t > r.t) ++c.farther, bad = true;
      else ++c.nearer, bad = true;
    }
    if (bad && c.first_bad_ray == UINT64_MAX) c.first_bad_ray = i;
  }
  return c;
}

}  // namespace bsprt
