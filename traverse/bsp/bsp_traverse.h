#pragma once
/// \file bsp_traverse.h
/// Ray casting through the flat BSP tree (bsp_node.h): single rays front to back
/// with a fixed stack and early exit, and SIMD packets of 4/8/16 rays, both
/// *certified*: a ray whose exact path meets a triangle inside a leaf's cell
/// before its nearest hit visits that leaf (docs/certified-epsilons.md). BSP
/// nodes cost two dot products (Ize, Wald, Parker, RT 2008, §5); axis-aligned
/// splits use the kd formula. The conservative interval logic follows the
/// spirit of Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013: bound every
/// rounding and widen, never trust a float comparison near the plane. Leaves
/// use the watertight test (watertight.h).

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "geometry/core/triangle_soup.h"
#include "traverse/bsp/bsp_boxtop.h"
#include "traverse/bsp/bsp_compact.h"
#include "traverse/bsp/bsp_node.h"
#include "traverse/bvh/bvh8_traverse.h"
#include "traverse/leaf_intersector.h"
#include "traverse/accelerator.h"

namespace bsprt {

/// Which slab bounds traversal uses (STYLE.md 8: robustness explicit in types).
enum class BspEpsilon {
  /// The certified bounds: per-node eps from the exact cell plus the per-ray
  /// rounding bound of the plane evaluation. No lost hit (docs).
  Certified,
  /// All slab bounds zero (the crossing t is still widened by a few ulps): the
  /// naive float traversal, kept to measure what certification costs. May
  /// lose hits near planes.
  Zero,
};

/// How BspTracer::trace_batch runs single rays. Every choice makes each ray's
/// steps of trace() in the same order, so hits are the same bit for bit; only
/// speed differs.
enum class BspSingleRays {
  /// Interleaved when the batch looks incoherent (not rays_look_coherent),
  /// its rays are unbounded (rays_unbounded) and the tree is too large to stay
  /// in the L1 data cache (BspTracer::walk_bytes() >= kInterleaveMinBytes);
  /// else sequential. Shadow rays (short segments to a light) were slower
  /// interleaved, and so were the small scenes' trees, whose loads never wait
  /// (docs/certified-epsilons.md §11, docs/notes/2026-11-22-interleaved-single-rays.md).
  Auto,
  /// One ray after the other, the branchy loop of trace(): fastest on
  /// coherent rays, whose branches the CPU predicts.
  Sequential,
  /// Eight rays in flight, each inner step choosing its child without a
  /// branch: fastest on long incoherent rays (random, vertex- and
  /// edge-aimed).
  Interleaved,
};

/// Smallest tree (BspTracer::walk_bytes) that BspSingleRays::Auto interleaves.
/// Below it the nodes and leaf triangles stay in the L1 data cache (48 KiB on
/// the AMD EPYC of docs/performance.md, 32 KiB on most x86 cores), so no load
/// waits for the other rays to overlap, and the interleaved kernel's extra
/// work per step is not repaid: on the shared scenes' trees of 0.3-7 KB
/// vertex-aimed rays ran 1.4-2.2x slower interleaved, while trees of 59 KB and
/// more ran 4-33 % faster (docs/notes/2026-12-08-small-trees-sequential.md).
inline constexpr std::size_t kInterleaveMinBytes = 32 * 1024;

/// Whether a batch looks coherent, like camera rays in tiles: at least half of
/// up to 16 evenly spaced pairs of neighbouring rays have directions within
/// about 8 degrees of each other. Picks the single-ray kernel only.
bool rays_look_coherent(std::span<const Ray> rays);

/// Whether the rays of one packet are coherent enough for the packet kernel:
/// every ray with a finite, nonzero direction is within about 8 degrees of the
/// first such ray (cos^2 > 0.98, the test rays_look_coherent makes between
/// neighbours). Picks the kernel only; hits are the same either way.
bool packet_looks_coherent(std::span<const Ray> rays);

/// How BspTracer::trace_batch runs a batch asked for in packets. Each lane of
/// a packet makes the single ray's steps, so hits are the same bit for bit;
/// only speed differs.
enum class BspPackets {
  /// A packet whose rays are not coherent (packet_looks_coherent) runs as
  /// single rays, as set_single_rays says: its lanes would part at most plane
  /// nodes, and the packet kernel then runs slower than single rays (random,
  /// vertex, edge and path-traced rays, docs/certified-epsilons.md §5). The
  /// kd-tree's packets do the same for rays of mixed direction signs.
  Auto,
  /// Every packet through the packet kernel (tests of the kernel itself).
  Always,
};

/// Whether at least half of up to 16 evenly spaced rays of a batch have
/// tfar = +inf (an empty batch: false). Picks the single-ray kernel only.
bool rays_unbounded(std::span<const Ray> rays);

/// The flat BSP tree behind the Accelerator interface. Copies the triangle corners
/// it needs, so the soup need not outlive it.
class BspTracer final : public Accelerator {
 public:
  /// Takes ownership of `tree`, built for `soup`. Throws UsageError when the
  /// tree fails FlatBspTree::validate(), is deeper than kBspMaxDepth (128), or
  /// was built for a scene with another triangle count.
  BspTracer(FlatBspTree tree, const TriangleSoup& soup, BspEpsilon mode = BspEpsilon::Certified);

  /// bsp (exact leaves), bsp-float, bsp-zero-eps; with a box top bsp-top,
  /// bsp-top-float, bsp-top-zero-eps.
  /// With a BVH8 top bsp-bvh8, bsp-bvh8-float, bsp-bvh8-zero-eps.
  std::string name() const override {
    const std::string base = exact_leaf_ ? "bsp" : (mode_ == BspEpsilon::Zero ? "bsp-zero-eps" : "bsp-float");
    if (wide_) return "bsp-bvh8" + base.substr(3);
    return has_top_ ? "bsp-top" + base.substr(3) : base;
  }
  /// Tests leaves with `exact` (exact decisions, robust/certified_intersector.h)
  /// instead of the float watertight test; it must outlive the tracer. With
  /// certified epsilons this makes every decision exact: the nearest hit equals
  /// the exact reference's. Packets run the exact test lane by lane.
  void set_exact_leaf(const LeafIntersector* exact) {
    exact_leaf_ = exact;
    if (wide_) wide_->set_exact_leaf(exact);
  }
  /// Single ray, front to back; counts bsp_node_visits, kd_node_visits,
  /// leaf_visits, triangle_tests and rays when `counters` is non-null.
  Hit trace(const Ray& ray, RayCounters* counters = nullptr) const override;
  /// packet_width 1 = single rays (run as set_single_rays says); 4, 8, 16 =
  /// SSE4.2, AVX2, AVX-512 packets (UsageError when the CPU lacks the ISA).
  /// Each lane runs exactly the single-ray steps (lanes that disagree on a
  /// node's near child wait on the stack), so hits and counters equal single
  /// rays bit for bit. With a box top packets run as single rays; with
  /// exact leaves each active lane runs the exact test at a leaf. With
  /// counters or a box top single rays run sequentially, and so do packets
  /// with exact leaves when counted. Packets whose rays are not coherent run
  /// as single rays unless set_packets(BspPackets::Always).
  void trace_batch(std::span<const Ray> rays, std::span<Hit> hits, int packet_width = 1,
                   RayCounters* counters = nullptr) const override;
  /// The tree cut into subtrees of at most `max_slots` slots, with their
  /// certified boxes (bsp_boxtop.h), to build a box top from.
  /// With max_triangles > 0, subtrees listing at most that many distinct
  /// triangles are cut too (bsp_subtree_boxes).
  std::vector<BspSubtreeBox> subtree_boxes(std::uint32_t max_slots, std::uint32_t max_triangles = 0) const;
  /// Traces single rays through `top` (built from subtree_boxes()) before the
  /// BSP subtrees; packets then run as single rays.
  void set_box_top(BoxTop top);
  bool has_box_top() const { return has_top_; }
  /// Traces single rays through `top`, a BVH8 over pieces of this tree
  /// (Bvh8Tree::over_bsp, built by traverse/embree/bvh8_build.h from
  /// subtree_boxes()), with Bvh8Tracer's kernel; its kSubtree leaves run the
  /// certified BSP steps from the subtree's root, inside the subtree's box
  /// (issue #26 step two, docs/bvh8.md). Rays the BSP scales or finds unsafe
  /// (bsp_kernel.h) take the plain BSP traversal. Packets run as single rays.
  /// Throws UsageError when `top` fails validation or names a slot that is
  /// not in the tree.
  void set_bvh8_top(Bvh8Tree top);
  bool has_bvh8_top() const { return wide_ != nullptr; }
  const Bvh8Tracer* bvh8_top() const { return wide_.get(); }
  /// The BVH8 top's kernel ISA (Bvh8Tracer::set_kernel_isa); tests compare them.
  void set_bvh8_kernel_isa(Isa isa) {
    if (wide_) wide_->set_kernel_isa(isa);
  }
  /// Test hook: Bvh8Tracer::shrink_boxes_for_testing on the BVH8 top's node boxes.
  void shrink_bvh8_top_for_testing() {
    if (wide_) wide_->shrink_boxes_for_testing();
  }
  /// Any hit in [tnear, tfar]: with a BVH8 top its any-hit kernel; with a box
  /// top (bsp-top) trace(ray).hit(); otherwise the traversal of trace, stopped
  /// after the first leaf that yields a hit (exact leaves decide it exactly).
  bool occluded(const Ray& ray, RayCounters* counters = nullptr) const override;
  /// The leaf lists: triangle numbers and their corners (compact().slots'
  /// prim_offset indexes both).
  std::span<const std::uint32_t> leaf_prims() const { return tree_.prims; }
  std::span<const BspTriangle> leaf_triangles() const { return triangles_; }
  /// Triangles of the scene the tree was built for.
  std::uint32_t scene_triangles() const { return std::uint32_t(tree_.triangle_count); }
  /// How trace_batch runs single rays (default Auto); not while tracing.
  void set_single_rays(BspSingleRays how) { single_rays_ = how; }
  BspSingleRays single_rays() const { return single_rays_; }
  /// How trace_batch runs packets (default Auto); not while tracing.
  void set_packets(BspPackets how) { packets_ = how; }
  BspPackets packets() const { return packets_; }
  const BoxTop& box_top() const { return top_; }
  /// Nodes, leaf lists, the copied triangles and the box top.
  std::size_t memory_bytes() const override;
  /// What a walk without a top reads: the compact nodes and the leaves'
  /// triangle numbers and corners.
  std::size_t walk_bytes() const;
  /// Whether trace_batch runs these single rays interleaved (set_single_rays;
  /// Auto: see BspSingleRays::Auto). Counted batches, box tops and BVH8 tops
  /// always run sequentially.
  bool interleaves(std::span<const Ray> rays, bool counted = false) const;

  BspEpsilon mode() const { return mode_; }
  /// The traversal layout made from the tree (bsp_compact.h).
  const CompactBspTree& compact() const { return compact_; }

 private:
  FlatBspTree tree_;  ///< bounds, leaf lists; nodes dropped after compacting
  CompactBspTree compact_;
  BspEpsilon mode_;
  const LeafIntersector* exact_leaf_ = nullptr;
  std::vector<BspTriangle> triangles_;  ///< triangles_[i] = corners of tree_.prims[i]
  BoxTop top_;
  bool has_top_ = false;
  std::unique_ptr<Bvh8Tracer> wide_;  ///< the BVH8 top, or null
  bool wide_safe_scene_ = false;      ///< root cell within the BVH8 kernel's range (2^64)
  BspSingleRays single_rays_ = BspSingleRays::Auto;
  BspPackets packets_ = BspPackets::Auto;
};

}  // namespace bsprt
