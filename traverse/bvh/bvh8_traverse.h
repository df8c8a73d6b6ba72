#pragma once
/// \file bvh8_traverse.h
/// Single rays through a plain BVH8 (bvh8_node.h) with the Embree-style box
/// kernel of bvh8_kernel.inl (AVX-512 or AVX2 when the CPU has it, else the
/// same source for plain x86-64). The box test is conservative (docs/bvh8.md): no hit of
/// the exact ray is lost, so with an exact leaf test the nearest hit equals
/// the exact reference's; with the float watertight test it equals brute
/// force's up to ties.

#include <memory>

#include "traverse/accelerator.h"
#include "traverse/bvh/bvh8_node.h"
#include "traverse/leaf_intersector.h"
#include "traverse/simd/cpu_features.h"

namespace bsprt {
namespace detail {
struct Bvh8View;
using Bvh8SubtreeFn = void (*)(void* ctx, std::uint32_t subtree, Hit& hit, NearestHit& nearest, RayCounters* c);
}

/// The BVH8 behind the Accelerator interface.
class Bvh8Tracer final : public Accelerator {
 public:
  /// Takes ownership of `tree`; throws UsageError when it fails
  /// Bvh8Tree::validate() or is deeper than the kernel's stack allows.
  explicit Bvh8Tracer(Bvh8Tree tree);

  /// bvh8 with an exact leaf test (set_exact_leaf), else bvh8-float.
  std::string name() const override { return exact_leaf_ ? "bvh8" : "bvh8-float"; }
  /// Tests leaves with `exact` instead of the float watertight test; it must
  /// outlive the tracer. The traversal culls against cull_bound.
  void set_exact_leaf(const LeafIntersector* exact) { exact_leaf_ = exact; }
  /// Single ray; counts box_node_visits, leaf_visits, triangle_tests and rays
  /// (and the exact leaf test's own counters) when `counters` is non-null.
  /// A ray whose origin, or a scene whose corners, exceed 2^126 in magnitude
  /// (where p - o could overflow) is traced against every triangle instead.
  Hit trace(const Ray& ray, RayCounters* counters = nullptr) const override;
  /// trace() for every ray, the loop inside the ISA's kernel file (no
  /// virtual call or ISA switch per ray); single rays whatever packet_width.
  void trace_batch(std::span<const Ray> rays, std::span<Hit> hits, int packet_width = 1,
                   RayCounters* counters = nullptr) const override;
  /// Any hit in [tnear, tfar]: the nearest-hit traversal stopped at the first
  /// hit a leaf proves (exactly, with an exact leaf test), so equal to
  /// trace(ray).hit() at a fraction of the work on rays that hit.
  bool occluded(const Ray& ray, RayCounters* counters = nullptr) const override;
  std::size_t memory_bytes() const override { return tree_.memory_bytes(); }
  /// A tree over a BSP (Bvh8Tree::over_bsp; trace() refuses it): the same
  /// kernel, with `fn(ctx, ...)` tracing the ray through the BSP subtrees
  /// (BspTracer::set_bvh8_top). No fallback for huge coordinates: the caller
  /// keeps the ray and the scene within the BSP's safe range.
  Hit trace_with(const Ray& ray, detail::Bvh8SubtreeFn fn, void* ctx, RayCounters* counters) const;
  bool occluded_with(const Ray& ray, detail::Bvh8SubtreeFn fn, void* ctx, RayCounters* counters) const;

  const Bvh8Tree& tree() const { return tree_; }
  /// The kernel's ISA: Avx512 or Avx2 (the widest the CPU has) or Scalar (plain x86-64).
  Isa kernel_isa() const { return isa_; }
  /// Uses the plain x86-64 kernel (Isa::Scalar or Sse42), the AVX2 or the
  /// AVX-512 one (UsageError when the CPU lacks it); tests compare them.
  void set_kernel_isa(Isa isa);
  /// Test hook: moves every box face inward by one float step, so that the
  /// tests can show that the tight boxes are needed (hits then go missing).
  void shrink_boxes_for_testing();

 private:
  Hit trace_every_triangle(const Ray& ray, RayCounters* counters) const;
  detail::Bvh8View view() const;
  /// The kernel of isa_ (the ISA switch, once).
  Hit run(const detail::Bvh8View& v, const Ray& ray, RayCounters* counters) const;
  bool run_occluded(const detail::Bvh8View& v, const Ray& ray, RayCounters* counters) const;

  Bvh8Tree tree_;
  const LeafIntersector* exact_leaf_ = nullptr;
  Isa isa_ = Isa::Scalar;
  bool huge_scene_ = false;  ///< some corner beyond 2^126 in magnitude
};

}  // namespace bsprt
