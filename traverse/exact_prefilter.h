#pragma once
/// \file exact_prefilter.h
/// A float filter in front of the exact-decision leaf test (leaf_intersector.h):
/// up to four triangles at once, it proves in float, with a forward error
/// bound, that a triangle's edge weights have opposite signs, so that the exact
/// test would call it a miss, and leaves such triangles out (docs/bvh8.md,
/// "Exact leaves"). Used by the BVH8 and the kd-tree in front of their exact
/// leaves. Inline, in the ISA namespace of simd.h (per-ISA kernels include it).

#include <cmath>
#include <cstdint>
#include <cstring>

#include "bsprt/ray.h"
#include "traverse/leaf_intersector.h"
#include "traverse/simd/simd.h"
#include "traverse/watertight.h"

namespace bsprt::detail {
inline namespace BSPRT_ISA_NAMESPACE {

/// The lanes (bits) of a leaf that the exact leaf test must see: a lane is
/// left out when float arithmetic with a forward error bound proves that two
/// of its edge weights have opposite signs, so the exact test would call it a
/// miss (docs/bvh8.md, "Exact leaves"). The weights are the watertight test's
/// sheared 2D cross products of the corners relative to the origin; in float
/// their error is below 20.1 u Mx My (u = 2^-24, Mx and My bound
/// |a[kx]| + |sx| |a[kz]| and |a[ky]| + |sy| |a[kz]| over the corners) plus
/// 2^-149 (Mx + My + 1) from underflowing products; the bound used,
/// max(2^-18 Mx My, 2^-145 (Mx + My), 2^-120), covers both. The relative
/// bound needs a normal shear: a ray whose nonzero sx or sy is below 2^-126
/// (`filterable` false) keeps every lane, as does a NaN or infinite bound.
/// Regression tests "bvh8: a subnormal shear ..." and "bvh8: an underflowing
/// shear product ..." (tests/test_bvh8.cpp; found in review).
inline bool filterable(const WatertightRay& r, const Ray& ray) {
  const auto normal_or_exact_zero = [](float s, float d) { return d == 0.0f || std::abs(s) >= 0x1p-126f; };
  return normal_or_exact_zero(r.sx, ray.dir[r.kx]) && normal_or_exact_zero(r.sy, ray.dir[r.ky]);
}

/// The filter's error bound max(2^-18 Mx My, 2^-145 (Mx + My), 2^-120),
/// computed as max(2^-18 Mx My, (max(Mx + My, 2^25) 2^-25) 2^-120): the same
/// value bit for bit (2^-145 s is at most 2^-120 when s < 2^25, and both
/// scalings are exact), NaN and infinity included, with no subnormal operand or
/// result. The constant 2^-145 is itself subnormal, and so was the product for
/// any scene of ordinary size: on x86 each such multiplication takes a
/// microcode assist (perf: a third of the kd-tree's exact leaf time on
/// conference camera rays). Test: "exact prefilter: the bound equals its
/// formula".
/// W lanes at once (W = 4 unless given; the packet filter, exact_packet_filter.h).
template <int W = 4>
inline simd::vfloat<W> exact_filter_bound(simd::vfloat<W> mx, simd::vfloat<W> my) {
  const simd::vfloat<W> scaled = simd::max<W>(mx + my, simd::splat<W>(0x1p25f)) * 0x1p-25f;
  return simd::max<W>(0x1p-18f * (mx * my), scaled * 0x1p-120f);
}

/// The filter on up to four triangles whose corner rows `lane(c, k)` gives:
/// the four floats of corner c, axis k (lanes past `count` are masked off).
template <class Lane>
inline unsigned exact_lanes_with(const WatertightRay& r, Lane&& lane, std::uint32_t count) {
  using V4 = simd::vfloat<4>;
  using M4 = simd::vmask<4>;
  const V4 sx = simd::splat<4>(r.sx), sy = simd::splat<4>(r.sy);
  const V4 asx = simd::abs<4>(sx), asy = simd::abs<4>(sy);
  // The origin's sheared axes once (Vec3's operator[] with a run-time axis is a select chain).
  const float ox = r.org[r.kx], oy = r.org[r.ky], oz = r.org[r.kz];
  V4 x[3], y[3], mx = simd::splat<4>(0.0f), my = simd::splat<4>(0.0f);
  for (int c = 0; c < 3; ++c) {
    const V4 az = lane(c, r.kz) - oz, ax = lane(c, r.kx) - ox, ay = lane(c, r.ky) - oy;
    x[c] = ax - no_fma(sx * az);
    y[c] = ay - no_fma(sy * az);
    const V4 aaz = simd::abs<4>(az);
    mx = simd::max<4>(simd::abs<4>(ax) + asx * aaz, mx);
    my = simd::max<4>(simd::abs<4>(ay) + asy * aaz, my);
  }
  const V4 u = no_fma(x[1] * y[2]) - no_fma(y[1] * x[2]);
  const V4 v = no_fma(x[2] * y[0]) - no_fma(y[2] * x[0]);
  const V4 w = no_fma(x[0] * y[1]) - no_fma(y[0] * x[1]);
  const V4 bound = exact_filter_bound(mx, my);
  const M4 pos = (u > bound) | (v > bound) | (w > bound);
  const M4 neg = (u < -bound) | (v < -bound) | (w < -bound);
  const unsigned all = (1u << count) - 1u;
  return all & ~simd::movemask<4>(pos & neg);
}

/// `rows` holds nine rows of `count` (1..4) floats (corner c, axis k at row
/// 3c + k), each read as four floats: rows[8 count + 3] must be readable.
inline unsigned exact_lanes(const WatertightRay& r, const float* rows, std::uint32_t count) {
  return exact_lanes_with(r, [&](int c, int k) { return simd::load<4>(rows + (3 * c + k) * count); }, count);
}

/// The same on the corners of up to four triangles, given by pointer
/// (t[j] for j >= count may be any triangle: masked off). The rows are built
/// in registers from the triangles as stored: a row written to memory float by
/// float and read back as one vector cannot be forwarded from the stores
/// (perf: the hottest instructions of the kd-tree's exact leaves on conference
/// camera rays, when kd_exact_leaf gathered the rows into a buffer).
inline unsigned exact_lanes(const WatertightRay& r, const LeafTriangle* const (&t)[4], std::uint32_t count) {
  const auto at = [](const LeafTriangle* p, int i) {
    float f;
    std::memcpy(&f, reinterpret_cast<const char*>(p) + sizeof(float) * std::size_t(i), sizeof f);
    return f;
  };
  return exact_lanes_with(
      r,
      [&](int c, int k) {
        const int i = 3 * c + k;
        return simd::vfloat<4>{at(t[0], i), at(t[1], i), at(t[2], i), at(t[3], i)};
      },
      count);
}

}  // namespace BSPRT_ISA_NAMESPACE
}  // namespace bsprt::detail
