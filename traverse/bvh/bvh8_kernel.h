#pragma once
/// \file bvh8_kernel.h
/// Internal to the BVH8 tracer: the raw view of a tree that the per-ISA
/// single-ray kernels (bvh8_kernel.inl) read, the per-ray constants they
/// share, and their entry points.

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "bsprt/ray.h"
#include "traverse/bvh/bvh8_node.h"
#include "traverse/counters.h"
#include "traverse/leaf_intersector.h"

namespace bsprt::detail {

/// Traces the ray of `ctx` through BSP subtree `subtree` (a kSubtree
/// reference, bvh8_node.h): with an exact leaf test into `nearest`, else into
/// `hit` (bsp_traverse.cpp, BspTracer's BVH8 top). The kernel then lowers its
/// tfar from the result as after a triangle leaf.
using Bvh8SubtreeFn = void (*)(void* ctx, std::uint32_t subtree, Hit& hit, NearestHit& nearest, RayCounters* c);

/// Raw pointers into a Bvh8Tracer.
struct Bvh8View {
  const Bvh8Node* nodes;
  const float* leaf_soa;               ///< SoA rows of the leaf entries (the float test)
  const std::uint32_t* prims;
  const LeafTriangle* triangles;       ///< corners of prims[i]
  const LeafIntersector* exact_leaf;   ///< exact-decision leaf test, or null = float watertight
  Bvh8SubtreeFn subtree = nullptr;     ///< a tree over a BSP: traces its subtrees
  void* subtree_ctx = nullptr;         ///< the ray's state for `subtree`
};

/// Traversal stack entries: at most 7 per level of inner nodes, plus one.
inline constexpr std::uint32_t kBvh8MaxDepth = 64;
inline constexpr int kBvh8StackSize = 7 * int(kBvh8MaxDepth) + 1;

/// Per-ray reciprocals of the conservative box test (docs/bvh8.md): for every
/// axis, rn and rf bracket 1/d with |rn| <= 1 / (|d| (1 + 2^-24)) and
/// |rf| >= 1 / (|d| (1 - 2^-24)), with the sign of d; for d = +-0 both are
/// the infinity of d's sign.
struct Bvh8RayRecip {
  float rn[3], rf[3];
};

/// r = fl(1/d) is within 2^-24 |1/d| of 1/d (IEEE division), so the bounds
/// need |r| (1 -+ 2^-24)^(+-2), a little more than 2^-23 relative: three float
/// steps of |r| (each at least 2^-24 |r| for normal |r|, more for subnormal)
/// give rf, three steps down give rn. An infinite r (d = 0, or |d| so small
/// that 1/d overflows) stays infinite in rf; rn is infinite only for d = 0.
inline Bvh8RayRecip bvh8_reciprocals(const Ray& ray) {
  Bvh8RayRecip r;
  for (int k = 0; k < 3; ++k) {
    const float d = ray.dir[k];
    const float q = 1.0f / d;
    const std::uint32_t sign = std::bit_cast<std::uint32_t>(q) & 0x80000000u;
    const std::uint32_t mag = std::bit_cast<std::uint32_t>(q) & 0x7fffffffu;  // at least 1/FLT_MAX's bits
    const std::uint32_t up = mag >= 0x7f7ffffdu ? 0x7f800000u : mag + 3u;
    const std::uint32_t down = d == 0.0f ? mag : mag - 3u;
    r.rn[k] = std::bit_cast<float>(sign | down);
    r.rf[k] = std::bit_cast<float>(sign | up);
  }
  return r;
}

/// The kernels trace a ray whose origin lies within 2^126 of 0 in every
/// coordinate (so that p - o cannot overflow in the box test); Bvh8Tracer
/// traces any other ray against every triangle.
inline constexpr float kBvh8Huge = 0x1p126f;
inline bool bvh8_origin_in_range(const Ray& ray) {
  return std::fabs(ray.org.x) <= kBvh8Huge && std::fabs(ray.org.y) <= kBvh8Huge && std::fabs(ray.org.z) <= kBvh8Huge;
}

/// Traces a ray the kernels do not take (bvh8_origin_in_range false).
using Bvh8FallbackFn = Hit (*)(const void* ctx, const Ray& ray, RayCounters* c);

/// Nearest hit of one ray; counts into c when non-null. Call the AVX2 and
/// AVX-512 ones only when detected_isa() supports them; the base one (plain
/// x86-64) runs anywhere. All three return the same hits, bit for bit.
Hit bvh8_trace_avx512(const Bvh8View& view, const Ray& ray, RayCounters* c);
Hit bvh8_trace_avx2(const Bvh8View& view, const Ray& ray, RayCounters* c);
Hit bvh8_trace_base(const Bvh8View& view, const Ray& ray, RayCounters* c);
/// rays[i] into hits[i] for i < n: what the single-ray entry does ray by ray,
/// the loop inside the ISA's kernel file (no virtual call, ISA switch or
/// tracer checks per ray; GCC keeps the kernel a direct call).
/// Rays out of range go to fallback(ctx, ray, c).
void bvh8_trace_batch_avx512(const Bvh8View& view, const Ray* rays, Hit* hits, std::size_t n, RayCounters* c,
                             Bvh8FallbackFn fallback, const void* ctx);
void bvh8_trace_batch_avx2(const Bvh8View& view, const Ray* rays, Hit* hits, std::size_t n, RayCounters* c,
                           Bvh8FallbackFn fallback, const void* ctx);
void bvh8_trace_batch_base(const Bvh8View& view, const Ray* rays, Hit* hits, std::size_t n, RayCounters* c,
                           Bvh8FallbackFn fallback, const void* ctx);
/// Any hit in [tnear, tfar]: the same traversal, stopped at the first hit.
bool bvh8_occluded_avx512(const Bvh8View& view, const Ray& ray, RayCounters* c);
bool bvh8_occluded_avx2(const Bvh8View& view, const Ray& ray, RayCounters* c);
bool bvh8_occluded_base(const Bvh8View& view, const Ray& ray, RayCounters* c);

}  // namespace bsprt::detail
