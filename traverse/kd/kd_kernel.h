#pragma once
/// \file kd_kernel.h
/// Internal to the kd traversal: the raw view of a tree that the scalar code
/// and the per-ISA packet kernels (kd_packet.inl) share, the interval widening
/// constants both must use identically, and the kernel entry points.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <type_traits>

#include "bsprt/ray.h"
#include "traverse/counters.h"
#include "traverse/kd/kd_traverse.h"
#include "traverse/exact_double_stage.h"
#include "traverse/exact_prefilter.h"
#include "traverse/simd/simd.h"
#include "traverse/watertight.h"

namespace bsprt::detail {

/// t is widened to [t * kKdTLo, t * kKdTHi] (ordered): 2^-21 = 8 float ulps,
/// more than the <= 3 ulps of error of (split - o) * (1/d) and of its rounding.
inline constexpr float kKdTLo = 1.0f - 0x1p-21f;
inline constexpr float kKdTHi = 1.0f + 0x1p-21f;

/// 1/d for the traversal: NaN when d is subnormal. Then 1/d may overflow
/// while the crossings (s - o)/d are still finite, and an infinite reciprocal
/// would put every crossing of that axis at ±inf and cull the cells the ray
/// reaches at a finite t. A NaN crossing culls nothing (both children, the
/// whole interval), as in the BSP's setup (bsp_kernel.h, ray_setup_core).
/// Regression test "kd and exact packets: a subnormal direction component
/// loses no hit" (tests/test_bsp_traverse.cpp).
///
/// NaN too when (s - o) could overflow for a split s in the root box:
/// |o| + reach >= 2^127, reach = max(|lo|, |hi|) of the root box on that axis
/// (kd_reach). An overflowed difference is ±inf where the crossing is finite
/// (a plane at -3.4e38 seen from 1e38 is crossed at t = 4.4e30 by a ray with
/// d = -1e8) and put the ray's whole interval on one side. The float sum
/// errs by half an ulp, far inside the factor of two to the overflow
/// threshold. Regression test "kd: a crossing whose (s - o) overflows loses
/// no hit" (tests/test_regressions.cpp).
inline float kd_reciprocal(float d, float o, float reach) {
  const bool normal_or_zero = d == 0.0f || std::fabs(d) >= 0x1p-126f;
  return normal_or_zero && std::fabs(o) + reach < 0x1p127f ? 1.0f / d : std::numeric_limits<float>::quiet_NaN();
}

/// max(|lo[k]|, |hi[k]|) of the root box: a bound on |s| for every split s.
inline float kd_reach(const Box3f& b, int k) { return std::max(std::fabs(b.lo[k]), std::fabs(b.hi[k])); }

/// Raw pointers into a KdTracer, for kernels that must not instantiate std::
/// templates compiled for their ISA.
struct KdView {
  const KdNode* nodes;
  const std::uint32_t* prims;
  const KdTriangle* triangles;  ///< by triangle number
  Box3f bounds;
  const LeafIntersector* exact_leaf = nullptr;  ///< exact-decision leaf test, or null = watertight float
};

inline namespace BSPRT_ISA_NAMESPACE {  // compiled into per-ISA kernels too (simd.h, ODR)

/// The exact leaf test on leaf entries [first, end) for one ray, four
/// triangles at a time: the float prefilter (exact_prefilter.h; when `filter`)
/// on their corners as stored, leaving out the certain misses, then the
/// staged exact test on each of the others, in leaf order. The nearest hit
/// and its tie rule do not depend on how the triangles are grouped, so the
/// answer is the one-at-a-time answer; left-out triangles still count as
/// tests. `er` holds the ray's double constants, made at the first triangle
/// that passes the prefilter (most rays' leaves need none).
///
/// Nothing is copied: the prefilter builds its rows in registers, and each
/// triangle that passes goes to the double stage from where it is stored.
/// Gathering rows and corners into stack buffers first, float by float, made
/// every vector read of them a store-forwarding stall (perf, conference camera
/// rays: the hottest instructions of these leaves).
template <bool kAnyHit = false>
inline void kd_exact_leaf(const KdView& v, std::uint32_t first, std::uint32_t end, const Ray& ray,
                          const WatertightRay& wr, bool filter, LazyExactRay& er, NearestHit& nearest,
                          RayCounters* c) {
  for (std::uint32_t i = first; i < end; i += 4) {
    const std::uint32_t n = end - i < 4 ? end - i : 4;
    unsigned lanes = 1u;
    if (n > 1) {  // one triangle: the double stage on it directly, no lane filter
      const LeafTriangle* t[4];
      for (std::uint32_t j = 0; j < 4; ++j) t[j] = &v.triangles[v.prims[i + (j < n ? j : 0)]];
      lanes = filter ? exact_lanes(wr, t, n) : (1u << n) - 1u;
      if (c) c->triangle_tests += n - std::uint32_t(__builtin_popcount(lanes));
    }
    for (unsigned bits = lanes; bits != 0; bits &= bits - 1) {
      const std::uint32_t prim = v.prims[i + std::uint32_t(__builtin_ctz(bits))];
      exact_leaf_staged<kAnyHit>(*v.exact_leaf, ray, er.get(ray), &prim, &v.triangles[prim], 1, nearest, c);
    }
  }
}

}  // namespace BSPRT_ISA_NAMESPACE

/// Single-ray trace used by kernels for incoherent packets.
using KdSingleFn = Hit (*)(const KdView& view, const Ray& ray, RayCounters* counters);

/// Packet kernels: rays[0..count) into hits, W = 4 / 8 / 16 at a time. Call
/// only when detected_isa() supports them.
void kd_trace_packets_sse42(const KdView& view, const Ray* rays, std::size_t count, Hit* hits,
                            RayCounters* counters, KdSingleFn single);
void kd_trace_packets_avx2(const KdView& view, const Ray* rays, std::size_t count, Hit* hits,
                           RayCounters* counters, KdSingleFn single);
void kd_trace_packets_avx512(const KdView& view, const Ray* rays, std::size_t count, Hit* hits,
                             RayCounters* counters, KdSingleFn single);

}  // namespace bsprt::detail
