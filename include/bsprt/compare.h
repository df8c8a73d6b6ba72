#pragma once
/// \file compare.h
/// Ray-by-ray comparison of a tested hit file against a reference, with the
/// categories of shared/formats.md and the error vocabulary of `bsprt compare`.

#include <cstdint>
#include <span>

#include "bsprt/ray.h"

namespace bsprt {

/// Counts of each outcome; every ray lands in exactly one of the eight counts
/// from both_miss to nearer.
struct HitComparison {
  std::uint64_t rays = 0;
  std::uint64_t both_miss = 0;
  std::uint64_t same_triangle = 0;  ///< same prim, t within tolerance (it may differ by rounding)
  std::uint64_t t_off = 0;          ///< same prim, t beyond tolerance: the right triangle at a wrong t
  std::uint64_t tie = 0;            ///< different prim, same t within tolerance
  std::uint64_t lost = 0;           ///< reference hits, tested misses
  std::uint64_t extra = 0;          ///< tested hits, reference misses
  std::uint64_t farther = 0;        ///< tested t beyond tolerance past the reference (a leak)
  std::uint64_t nearer = 0;         ///< tested t beyond tolerance before the reference
  double max_t_ulps = 0.0;          ///< largest |t - t_ref| in ulps of t_ref over hits on both sides
  std::uint64_t first_bad_ray = UINT64_MAX;  ///< first lost/extra/farther/nearer/t_off ray

  /// True when nothing is lost, extra, farther, nearer or t_off.
  bool agrees() const { return lost == 0 && extra == 0 && farther == 0 && nearer == 0 && t_off == 0; }
};

/// Compares ray by ray; `rel_tol` (finite, >= 0) is the relative t tolerance
/// of a tie or of rounding on the same triangle. Throws UsageError if the
/// sizes differ, if rel_tol is negative or not finite, or if a record is not
/// a hit file's record (formats.md): a hit with a t that is not finite, or a
/// miss whose t is not +inf.
HitComparison compare_hits(std::span<const Hit> reference, std::span<const Hit> tested, double rel_tol = 1e-5);

/// What makes `h` no hit file record (formats.md: a hit has a finite t, a
/// miss is t = +inf with prim 0xFFFFFFFF), or null when it is one.
const char* hit_record_problem(const Hit& h);

/// Distance between two floats in units in the last place (0 when equal).
double ulp_distance(float a, float b);

}  // namespace bsprt
