#pragma once
/// \file kd_build.h
/// SAH kd-tree build after Wald and Havran, "On building fast kd-trees for ray
/// tracing, and on doing that in O(N log N)" (RT 2006): split events are sorted
/// once and split into the children without re-sorting (Sec. 4.3-4.4), with
/// perfect splits (triangles clipped to the node cell, Sec. 4.1) and the
/// paper's handling of planar triangles (Sec. 4.2, the p- / p+ side choice).

#include <cstddef>

#include "geometry/core/triangle_soup.h"
#include "traverse/kd/kd_tree.h"

namespace bsprt {

/// Cost model and limits of the kd build. Defaults are Wald and Havran's.
struct KdConfig {
  /// K_T: cost of one traversal step (Sec. 3, "K_T = 15").
  float traversal_cost = 15.0f;
  /// K_I: cost of one ray/triangle test (Sec. 3, "K_I = 20").
  float intersection_cost = 20.0f;
  /// lambda: factor on the cost of a split that cuts off an empty child
  /// (Sec. 3.3, "empty space bonus", 0.8 = 20% bonus).
  float empty_bonus = 0.8f;
  /// Deepest leaf allowed; 0 = automatic, round(8 + 1.3 log2 N) (pbrt's rule).
  /// Capped at kKdMaxDepth - 1 = 63, the traversal stack's size.
  int max_depth = 0;
  /// Nodes with at most this many triangles become leaves without evaluating
  /// splits (1 = only single-triangle nodes are forced leaves).
  int leaf_size = 1;
  /// Subtrees with at least this many triangles are built as separate oneTBB
  /// tasks (tbb::task_group); smaller ones on the current thread.
  int parallel_threshold = 4096;
  /// Perfect splits: clip straddling triangles to the child cells (Sec. 4.1);
  /// false = keep their unclipped bounds (faster build, worse tree).
  bool perfect_splits = true;
};

/// Figures of one build (for `bsprt build` and the benchmark).
struct KdBuildReport {
  double seconds = 0.0;        ///< wall time of build_kd
  std::size_t nodes = 0;       ///< all nodes
  std::size_t leaves = 0;      ///< all leaves
  std::size_t empty_leaves = 0;///< leaves with no triangle
  double avg_leaf_size = 0.0;  ///< triangle references per non-empty leaf
  int max_depth = 0;           ///< deepest leaf (root = 0)
  int depth_limit = 0;         ///< the depth limit that was used
  std::size_t bytes = 0;       ///< nodes + leaf lists
  std::size_t clipped = 0;     ///< straddling triangles clipped to child cells
  std::size_t dropped = 0;     ///< clipped triangles found not to touch a child
};

/// Builds a SAH kd-tree over the non-degenerate triangles of `soup` (degenerate
/// ones are never hit, so they are left out). Every triangle that touches a
/// leaf's closed cell is listed in that leaf, except a triangle lying in a split
/// plane, which goes to one side (Sec. 4.2); clipping rounds outward so this
/// never depends on rounding. Throws UsageError if the soup is too large for
/// KdNode's 30-bit offsets.
KdTree build_kd(const TriangleSoup& soup, const KdConfig& config = {},
                KdBuildReport* report = nullptr);

/// The depth limit build_kd uses for `n` triangles.
int kd_depth_limit(const KdConfig& config, std::size_t n);

/// Geometric check of a built tree against its scene, with exact arithmetic
/// (independent of the build's clipping): every non-degenerate triangle that
/// touches the closed cell of a node is listed in the subtree under it, in every
/// leaf whose cell it touches, except that a triangle whose part in a cell lies
/// in that cell's split plane needs to be found on one side only. Throws
/// std::logic_error naming the first triangle and node at fault. Slow: tests.
void validate_kd_coverage(const KdTree& tree, const TriangleSoup& soup);

}  // namespace bsprt
