#pragma once
/// \file compare.h
/// Ray-by-ray comparison of a tested hit file against a reference, with the
/// categories of shared/formats.md and the error vocabulary of `bsprt compare`.

#include <cstdint>
#include <span>

#include "bsprt/ray.h"

namespace bsprt {

/// Counts of each outcome; every ray lands in exactly one of the first six.
struct HitComparison {
  std::uint64_t rays = 0;
  std::uint64_t both_miss = 0;
  std::uint64_t same_triangle = 0;  ///< same prim (t may differ by rounding)
  std::uint64_t tie = 0;            ///< different prim, same t within tolerance
  std::uint64_t lost = 0;           ///< reference hits, tested misses
  std::uint64_t extra = 0;          ///< tested hits, reference misses
  std::uint64_t farther = 0;        ///< tested t beyond tolerance past the reference (a leak)
  std::uint64_t nearer = 0;         ///< tested t beyond tolerance before the reference
  double max_t_ulps = 0.0;          ///< largest |t - t_ref| in ulps of t_ref over hits on both sides
  std::uint64_t first_bad_ray = UINT64_MAX;  ///< first lost/extra/farther/nearer ray

  /// True when nothing is lost, extra, farther or nearer.
  bool agrees() const { return lost == 0 && extra == 0 && farther == 0 && nearer == 0; }
};

/// Compares ray by ray; `rel_tol` is the relative t tolerance of a tie or of
/// rounding on the same triangle. Throws UsageError if the sizes differ.
HitComparison compare_hits(std::span<const Hit> reference, std::span<const Hit> tested, double rel_tol = 1e-5);

/// Distance between two floats in units in the last place (0 when equal).
double ulp_distance(float a, float b);

}  // namespace bsprt
