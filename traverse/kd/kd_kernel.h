#pragma once
/// \file kd_kernel.h
/// Internal to the kd traversal: the raw view of a tree that the scalar code
/// and the per-ISA packet kernels (kd_packet.inl) share, the interval widening
/// constants both must use identically, and the kernel entry points.

#include <cstdint>

#include "bsprt/ray.h"
#include "traverse/counters.h"
#include "traverse/kd/kd_traverse.h"

namespace bsprt::detail {

/// t is widened to [t * kKdTLo, t * kKdTHi] (ordered): 2^-21 = 8 float ulps,
/// more than the <= 3 ulps of error of (split - o) * (1/d) and of its rounding.
inline constexpr float kKdTLo = 1.0f - 0x1p-21f;
inline constexpr float kKdTHi = 1.0f + 0x1p-21f;

/// Raw pointers into a KdTracer, for kernels that must not instantiate std::
/// templates compiled for their ISA.
struct KdView {
  const KdNode* nodes;
  const std::uint32_t* prims;
  const KdTriangle* triangles;  ///< by triangle number
  Box3f bounds;
  const LeafIntersector* exact_leaf = nullptr;  ///< exact-decision leaf test, or null = watertight float
};

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
