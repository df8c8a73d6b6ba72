#pragma once
/// \file kd_tree.h
/// The flat float kd-tree that traversal reads: 8-byte nodes in depth-first
/// order (first child adjacent, as pbrt's KdAccelNode and Mitsuba's KDNode) and
/// one array of leaf triangle lists. Built by builder/kd_build.h, stored by
/// builder/kd_file.h, traced by traverse/kd_traverse.h. No CGAL here.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bsprt/vec3.h"

namespace bsprt {

/// One kd-tree node, 8 bytes. Byte layout (little-endian):
///
///   offset  size  inner node                      leaf
///   0       4     float split (plane x_axis=split) uint32 triangle count
///   4       4     bits 0-1: axis (0, 1, 2)         bits 0-1: 3 (leaf flag)
///                 bits 2-31: index of the second   bits 2-31: offset of the
///                 (upper, x_axis >= split) child;  first triangle number in
///                 the first (lower) child is the   KdTree::prims
///                 next node (depth-first order)
///
/// The leaf count lives in the word an inner node uses for its split (pbrt's
/// KdAccelNode does the same), so no side array is needed. 30 bits limit a
/// tree to 2^30 nodes and 2^30 leaf references.
struct alignas(8) KdNode {
  union {
    float split;          ///< inner: plane position
    std::uint32_t count;  ///< leaf: number of triangles
  };
  std::uint32_t bits;  ///< axis or leaf flag (2 bits) | child or prim offset (30 bits)

  /// Largest offset a node can store.
  static constexpr std::uint32_t kMaxOffset = (1u << 30) - 1;

  static KdNode make_inner(int axis, float split_pos, std::uint32_t upper_child) {
    KdNode n;
    n.split = split_pos;
    n.bits = (upper_child << 2) | std::uint32_t(axis);
    return n;
  }
  static KdNode make_leaf(std::uint32_t prim_offset, std::uint32_t prim_count) {
    KdNode n;
    n.count = prim_count;
    n.bits = (prim_offset << 2) | 3u;
    return n;
  }
  bool is_leaf() const { return (bits & 3u) == 3u; }
  /// Split axis of an inner node (0, 1, 2).
  int axis() const { return int(bits & 3u); }
  /// Inner node: index of the upper child (the lower child is this index + 1).
  std::uint32_t upper_child() const { return bits >> 2; }
  /// Leaf: first entry in KdTree::prims.
  std::uint32_t prim_offset() const { return bits >> 2; }
  std::uint32_t prim_count() const { return count; }
};
static_assert(sizeof(KdNode) == 8, "KdNode must be 8 bytes");
static_assert(alignof(KdNode) == 8, "KdNode must be 8-byte aligned");

/// A flat kd-tree over one triangle soup. Node 0 is the root; an empty tree has
/// one empty leaf. Cells are closed boxes: node 0's cell is `bounds`, and an
/// inner node's cell is cut by its plane into the lower [lo, split] and upper
/// [split, hi] cells of its children.
struct KdTree {
  std::vector<KdNode> nodes;          ///< depth-first, root first
  std::vector<std::uint32_t> prims;   ///< leaf triangle lists (triangle numbers)
  Box3f bounds;                       ///< root cell: bounds of the non-degenerate triangles
  std::uint32_t triangle_count = 0;   ///< triangles of the scene (for checks)

  /// Bytes held by nodes and triangle lists.
  std::size_t memory_bytes() const {
    return nodes.size() * sizeof(KdNode) + prims.size() * sizeof(std::uint32_t);
  }
  /// Structural self-check (Embree's verify()): child indices in range and after
  /// their parent (so no cycles), every node reached once, split inside the
  /// parent cell, leaf lists inside `prims` and covering it exactly once,
  /// triangle numbers < triangle_count. Throws std::logic_error naming the
  /// first problem. The geometric check (every triangle touching a leaf cell is
  /// listed) is builder's validate_kd_coverage.
  void validate() const;
};

/// Figures of a kd-tree (for reports and `bsprt stats`).
struct KdTreeStats {
  std::size_t nodes = 0;          ///< all nodes
  std::size_t leaves = 0;         ///< leaves, empty or not
  std::size_t empty_leaves = 0;   ///< leaves with no triangle
  std::size_t references = 0;     ///< triangle references in leaves
  double avg_leaf_size = 0.0;     ///< references / non-empty leaves
  int max_depth = 0;              ///< deepest leaf (root = 0)
  std::size_t bytes = 0;          ///< memory_bytes()
};

/// Counts nodes, leaves, references and depth of `tree`.
KdTreeStats kd_tree_stats(const KdTree& tree);

}  // namespace bsprt
