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
/// infinity) gives ±infinity; below it the result is finite. CGAL::to_double
/// may be a double off (it truncates), so both float neighbours are checked.
/// A tie between two finite floats goes to the even one, as IEEE rounding does
/// (the staged leaf test rounds the same way, certified_intersector.cpp).
template <typename NT>
float nearest_float(const NT& x) {
  constexpr double kOverflow = 0x1.ffffffp127;
  constexpr float kInf = std::numeric_limits<float>::infinity(), kMax = std::numeric_limits<float>::max();
  if (!(x < NT(kOverflow))) return kInf;
  if (!(x > NT(-kOverflow))) return -kInf;
  float f0 = float(CGAL::to_double(x));
  if (std::isinf(f0)) f0 = std::copysign(kMax, f0);  // x below the threshold: the largest float is nearest
  float best = f0;
  NT err = CGAL::abs(NT(double(f0)) - x);
  for (const float f : {std::nextafter(f0, -kInf), std::nextafter(f0, kInf)}) {
    if (!std::isfinite(f)) continue;
    const NT e = CGAL::abs(NT(double(f)) - x);
    if (e < err || (e == err && (std::bit_cast<std::uint32_t>(f) & 1u) == 0)) best = f, err = e;
  }
  return best;
}

}  // namespace bsprt
