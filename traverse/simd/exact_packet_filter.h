#pragma once
/// \file exact_packet_filter.h
/// The float prefilter of the exact leaf test (exact_prefilter.h) for a packet:
/// W rays against one triangle, lanes in SIMD registers. A packet kernel with
/// exact leaves tests each triangle against all its active lanes here and
/// hands only the lanes this cannot prove missed to the scalar exact leaf test
/// (exact_double_stage.h), ray by ray, in leaf order. The float watertight
/// packet test does the same lane work, so exact packets no longer run the
/// scalar test for every (ray, triangle) pair of a leaf.
///
/// Lane i computes what exact_lanes() computes for ray i and this triangle:
/// the same IEEE operations on the same inputs in the same order (the shear of
/// watertight_precompute, no FMA), so the proof of exact_prefilter.h holds
/// lane by lane. Include it only from per-ISA kernel translation units.

#include <cmath>

#include "bsprt/ray.h"
#include "traverse/exact_prefilter.h"
#include "traverse/simd/simd.h"
#include "traverse/simd/watertight_packet.h"

namespace bsprt::simd {
inline namespace BSPRT_ISA_NAMESPACE {

/// filterable() (exact_prefilter.h) of each lane: its shear is normal or an
/// exact zero. `dir` is the packet's direction, as given to watertight_precompute_soa.
template <int W>
inline vmask<W> filterable_lanes(const WatertightPacket<W>& r, const vfloat<W> (&dir)[3]) {
  using watertight_detail::pick_axis;
  const vfloat<W> dx = pick_axis<W>(dir, r.kx0, r.kx1), dy = pick_axis<W>(dir, r.ky0, r.ky1);
  const vmask<W> okx = (dx == 0.0f) | (abs<W>(r.sx) >= 0x1p-126f);
  const vmask<W> oky = (dy == 0.0f) | (abs<W>(r.sy) >= 0x1p-126f);
  return okx & oky;
}

/// The lanes of `active` (and valid) that the exact leaf test must see for
/// triangle (v0, v1, v2): a lane in `filterable` is left out when the float
/// bound proves two of its weights of opposite signs (exact_lanes); a lane
/// not in `filterable` is always kept.
template <int W>
inline vmask<W> exact_packet_lanes(const WatertightPacket<W>& r, const Vec3f& v0, const Vec3f& v1, const Vec3f& v2,
                                   vmask<W> active, vmask<W> filterable) {
  active &= r.valid;
  const Vec3f* corner[3] = {&v0, &v1, &v2};
  const vfloat<W> asx = abs<W>(r.sx), asy = abs<W>(r.sy);
  vfloat<W> x[3], y[3], mx = splat<W>(0.0f), my = splat<W>(0.0f);
  for (int c = 0; c < 3; ++c) {
    const Vec3f& p = *corner[c];
    const vfloat<W> a[3] = {p.x - r.org[0], p.y - r.org[1], p.z - r.org[2]};
    vfloat<W> ax, ay, az;
    if (r.uniform) {
      ax = a[r.kx], ay = a[r.ky], az = a[r.kz];
    } else {
      using watertight_detail::pick_axis;
      ax = pick_axis<W>(a, r.kx0, r.kx1), ay = pick_axis<W>(a, r.ky0, r.ky1), az = pick_axis<W>(a, r.kz0, r.kz1);
    }
    x[c] = ax - no_fma(r.sx * az);
    y[c] = ay - no_fma(r.sy * az);
    const vfloat<W> aaz = abs<W>(az);
    mx = max<W>(abs<W>(ax) + no_fma(asx * aaz), mx);
    my = max<W>(abs<W>(ay) + no_fma(asy * aaz), my);
  }
  const vfloat<W> u = no_fma(x[1] * y[2]) - no_fma(y[1] * x[2]);
  const vfloat<W> v = no_fma(x[2] * y[0]) - no_fma(y[2] * x[0]);
  const vfloat<W> w = no_fma(x[0] * y[1]) - no_fma(y[0] * x[1]);
  const vfloat<W> bound = detail::exact_filter_bound<W>(mx, my);
  const vmask<W> pos = (u > bound) | (v > bound) | (w > bound);
  const vmask<W> neg = (u < -bound) | (v < -bound) | (w < -bound);
  return active & ~(pos & neg & filterable);
}

}  // namespace BSPRT_ISA_NAMESPACE
}  // namespace bsprt::simd
