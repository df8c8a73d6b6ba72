#pragma once
/// \file kd_traverse.h
/// Ray casting through a flat kd-tree (kd_tree.h): single rays front to back
/// with a small fixed stack, and SIMD packets of 4/8/16 coherent rays. Both are
/// conservative: the interval of a ray in a cell is widened by more than the
/// rounding error of t = (split - o) * (1/d), so a ray is never culled from a
/// cell holding its nearest hit; a ray lying in a split plane (0 * inf = NaN)
/// visits both children. Leaves use the watertight test (watertight.h), and
/// packets give bit-identical results to single rays.

#include <array>
#include <vector>

#include "geometry/core/triangle_soup.h"
#include "traverse/kd/kd_tree.h"
#include "traverse/leaf_intersector.h"
#include "traverse/accelerator.h"

namespace bsprt {

/// Deepest tree the traversal stack holds (build_kd never builds deeper).
inline constexpr int kKdMaxDepth = 64;

/// A triangle's corners (36 bytes), copied from the soup by triangle number: one
/// copy per triangle, not per leaf reference (a smaller footprint measured
/// faster than leaf-ordered copies, which duplicate ~6x on scanned meshes).
using KdTriangle = LeafTriangle;

/// The kd-tree behind the Accelerator interface. Copies the triangle corners it
/// needs, so the soup need not outlive it.
class KdTracer final : public Accelerator {
 public:
  /// Takes ownership of `tree`, built for `soup`. Throws UsageError when the
  /// tree fails KdTree::validate(), is deeper than kKdMaxDepth, or was built
  /// for a scene with another triangle count.
  KdTracer(KdTree tree, const TriangleSoup& soup);

  /// kd with an exact leaf test (set_exact_leaf), else kd-float.
  std::string name() const override { return exact_leaf_ ? "kd" : "kd-float"; }
  /// Tests leaves with `exact` (robust/certified_intersector.h) instead of the
  /// float watertight test; it must outlive the tracer. The traversal is
  /// conservative and culls against cull_bound, so the nearest hit then equals
  /// the exact reference's. Packets run the exact test lane by lane; counted
  /// packets run as single rays.
  void set_exact_leaf(const LeafIntersector* exact) { exact_leaf_ = exact; }
  /// Single ray, front to back; counts kd_node_visits, leaf_visits,
  /// triangle_tests and rays when `counters` is non-null.
  Hit trace(const Ray& ray, RayCounters* counters = nullptr) const override;
  /// Any hit in [tnear, tfar]: the traversal of trace, stopped after the first
  /// leaf that yields a hit (exact leaves decide it exactly, as trace does).
  bool occluded(const Ray& ray, RayCounters* counters = nullptr) const override;
  /// packet_width 1 = single rays; 4, 8, 16 = SSE4.2, AVX2, AVX-512 packets
  /// (UsageError when the CPU lacks the ISA). Packets whose rays' direction
  /// signs differ are traced as single rays. Counters equal single-ray counters.
  void trace_batch(std::span<const Ray> rays, std::span<Hit> hits, int packet_width = 1,
                   RayCounters* counters = nullptr) const override;
  /// Nodes, leaf lists and the copied triangles.
  std::size_t memory_bytes() const override;

  const KdTree& tree() const { return tree_; }

 private:
  KdTree tree_;
  std::vector<KdTriangle> triangles_;  ///< corners of triangle i (all of the soup)
  const LeafIntersector* exact_leaf_ = nullptr;
};

}  // namespace bsprt
