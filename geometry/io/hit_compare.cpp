#include "bsprt/compare.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>
#include <utility>

#include "bsprt/error.h"
#include "geometry/core/fp_env.h"

namespace bsprt {

const char* hit_record_problem(const Hit& h) {
  if (h.hit() && !std::isfinite(h.t)) return "a hit (prim set) whose t is not finite";
  if (!h.hit() && h.t != INFINITY) return "a miss (prim 0xFFFFFFFF) whose t is not +inf";
  return nullptr;
}

double ulp_distance(float a, float b) {
  const IeeeScope ieee;  // DAZ would make two subnormals equal (fp_env.h)
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
  const IeeeScope ieee;
  if (reference.size() != tested.size())
    throw UsageError("hit files differ in size: " + std::to_string(reference.size()) + " vs " +
                     std::to_string(tested.size()) + " rays");
  if (!(rel_tol >= 0.0 && std::isfinite(rel_tol)))
    throw UsageError("the relative t tolerance must be a finite number >= 0, not " + std::to_string(rel_tol));
  HitComparison c;
  c.rays = reference.size();
  for (std::size_t i = 0; i < reference.size(); ++i) {
    const Hit& r = reference[i];
    const Hit& t = tested[i];
    for (const auto& [h, side] : {std::pair{&r, "reference"}, std::pair{&tested[i], "tested"}})
      if (const char* why = hit_record_problem(*h))
        throw UsageError(std::string(side) + " hit of ray " + std::to_string(i) + ": " + why);
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
      if (r.prim == t.prim && std::abs(double(t.t) - double(r.t)) <= tol) ++c.same_triangle;
      else if (r.prim == t.prim) ++c.t_off, bad = true;
      else if (std::abs(double(t.t) - double(r.t)) <= tol) ++c.tie;
      else if (t.t > r.t) ++c.farther, bad = true;
      else ++c.nearer, bad = true;
    }
    if (bad && c.first_bad_ray == UINT64_MAX) c.first_bad_ray = i;
  }
  return c;
}

}  // namespace bsprt
