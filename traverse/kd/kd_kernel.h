#pragma once
/// \file kd_kernel.h
/// Internal to the kd traversal: the raw view of a tree that the scalar code
/// and the per-ISA packet kernels (kd_packet.inl) share, the interval widening
/// constants both must use identically, and the kernel entry points.

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
inline float kd_reciprocal(float d) {
  return (d == 0.0f || std::fabs(d) >= 0x1p-126f) ? 1.0f / d : std::numeric_limits<float>::quiet_NaN();
}

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
/// triangles at a time: their corners (stored by triangle number) gathered
/// into leaf order, the float prefilter (exact_prefilter.h; when `filter`)
/// leaving out the certain misses, one call for the rest. The nearest hit and
/// its tie rule do not depend on how the triangles are grouped, so the answer
/// is the one-at-a-time answer; left-out triangles still count as tests.
/// The ray's double constants are made per call, only when some triangle
/// passes the prefilter (measured: fewer instructions than keeping them per
/// ray, on sponza camera rays and bunny vertex rays).
inline void kd_exact_leaf(const KdView& v, std::uint32_t first, std::uint32_t end, const Ray& ray,
                          const WatertightRay& wr, bool filter, NearestHit& nearest, RayCounters* c) {
  // Neither buffer is zeroed as a whole: GCC clears a 144-byte array with
  // `rep stos`, whose start-up cost made these two clears the hottest
  // instructions of the kd-tree's exact leaves (perf, conference camera rays).
  float rows[36];  // nine rows of n, read four floats at a time: rows[8 n + 3] is the last read
  alignas(LeafTriangle) unsigned char corner_bytes[4 * sizeof(LeafTriangle)];
  LeafTriangle* const corners = reinterpret_cast<LeafTriangle*>(corner_bytes);
  static_assert(std::is_trivially_copyable_v<LeafTriangle>);
  for (std::uint32_t i = first; i < end; i += 4) {
    const std::uint32_t n = end - i < 4 ? end - i : 4;
    if (n == 1) {  // one triangle: the double stage on it directly, no gather and no lane filter
      const std::uint32_t prim = v.prims[i];
      exact_leaf_staged(*v.exact_leaf, ray, exact_ray_const(ray), &prim, &v.triangles[prim], 1, nearest, c);
      continue;
    }
    for (std::uint32_t j = 0; j < n; ++j) {
      const LeafTriangle& t = v.triangles[v.prims[i + j]];
      for (int k = 0; k < 9; ++k) rows[std::uint32_t(k) * n + j] = t.v[k / 3][k % 3];
    }
    // The last row's reads past 9 n (n < 4) land in lanes that exact_lanes masks
    // off; they are still given values.
    for (std::uint32_t r = 9 * n; r < 8 * n + 4; ++r) rows[r] = 0.0f;
    const unsigned lanes = filter ? exact_lanes(wr, rows, n) : (1u << n) - 1u;
    std::uint32_t prims[4];
    std::uint32_t m = 0;
    for (unsigned bits = lanes; bits != 0; bits &= bits - 1, ++m) {
      const std::uint32_t j = std::uint32_t(__builtin_ctz(bits));
      prims[m] = v.prims[i + j];
      std::memcpy(static_cast<void*>(corners + m), &v.triangles[prims[m]], sizeof(LeafTriangle));
    }
    if (c) c->triangle_tests += n - m;
    if (m) exact_leaf_staged(*v.exact_leaf, ray, exact_ray_const(ray), prims, corners, m, nearest, c);
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
