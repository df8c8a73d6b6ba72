#pragma once
/// \file nearest_float.h
/// Rounding an exact number to float as IEEE round-to-nearest does, overflow
/// included: the one rounding of the exact reference (exact_tracer.cpp) and the
/// certified leaf test (certified_intersector.cpp), so the two report the same
/// float t for the same exact t.

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include <CGAL/number_utils.h>

namespace bsprt {

/// The float nearest to the exact value x. |x| at or beyond the largest float
/// plus half an ulp (0x1.ffffffp127, where IEEE's ties-to-even goes to
/// infinity) gives ±infinity; below it the result is finite. The search starts
/// at CGAL::to_double(x) and walks float by float until x lies between the
/// midpoints to its neighbours (each a double, exactly), compared exactly, as
/// round_exact does (certified_intersector.cpp). A lazy exact number's
/// to_double comes from its interval and can be several floats off: checking
/// only the two neighbours of the start rounded the exact reference's t up to
/// 12 ulps wrong (a review of 2026-12-07 on far_1e7 grazing rays; regression
/// test in test_regressions.cpp). A tie between two finite floats goes to the
/// even one, as IEEE rounding does.
template <typename NT>
float nearest_float(const NT& x) {
  constexpr double kOverflow = 0x1.ffffffp127;
  constexpr float kInf = std::numeric_limits<float>::infinity(), kMax = std::numeric_limits<float>::max();
  if (!(x < NT(kOverflow))) return kInf;
  if (!(x > NT(-kOverflow))) return -kInf;
  float f = float(CGAL::to_double(x));
  if (std::isinf(f)) f = std::copysign(kMax, f);  // x below the threshold: the largest float is nearest
  const auto odd = [](float v) { return (std::bit_cast<std::uint32_t>(v) & 1u) != 0; };
  bool reseeded = false;
  for (;;) {
    const float down = std::nextafter(f, -kInf), up = std::nextafter(f, kInf);
    // Midpoints of two floats are doubles exactly; past the largest float, the overflow threshold.
    const NT m_lo(std::isfinite(down) ? (double(f) + double(down)) / 2 : -kOverflow);
    const NT m_hi(std::isfinite(up) ? (double(f) + double(up)) / 2 : kOverflow);
    if (x < m_lo || x > m_hi) {
      // The comparison that failed was decided exactly, which narrows a lazy
      // number's interval to its exact value: start once more from there, so
      // the walk is at most a float or two whatever the first estimate was.
      if (!reseeded) {
        reseeded = true;
        const float g = float(CGAL::to_double(x));
        if (g != f && std::isfinite(g)) {
          f = g;
          continue;
        }
      }
      f = x < m_lo ? down : up;
      continue;
    }
    if (x == m_lo && odd(f)) return down;  // ties to even
    if (x == m_hi && odd(f)) return up;
    return f + 0.0f;  // a t rounding to zero is +0, whatever its sign, in every exact mode
  }
}

}  // namespace bsprt
