#pragma once
/// \file bsp_node.h
/// The flat float BSP tree that traversal reads (Ize, Wald, Parker, "Ray
/// Tracing with the BSP Tree", RT 2008, §5): 16-byte kd nodes and leaves,
/// 32-byte plane nodes carrying a *certified* slab bound, depth-first with the
/// first child adjacent; axis-aligned splits stay kd nodes (the paper's "kd-tree
/// traversal for axis-aligned splits": no dot product); one array of leaf
/// triangle lists. Made once from the exact tree by builder/bsp_flatten.h; traced by
/// traverse/bsp_traverse.h (through its compact copy, bsp_compact.h). No CGAL here.

#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "bsprt/vec3.h"
#include "traverse/leaf_intersector.h"

namespace bsprt {

/// Deepest flat tree the traversal stacks hold (the exact builder's default
/// max_depth is 64).
inline constexpr int kBspMaxDepth = 128;

/// What a FlatBspNode is. Values 0..2 are kd nodes on that axis.
enum class FlatBspNodeKind : std::uint32_t { KdX = 0, KdY = 1, KdZ = 2, Plane = 3, Leaf = 4 };

/// One 16-byte slot of the flat BSP tree: kd nodes and leaves take one slot,
/// plane nodes two (head + tail), so the common kd node costs a quarter of a
/// cache line. Byte layout (little-endian):
///
///   offset size  kd node          leaf               plane head         plane tail
///   0      4     bits             bits               bits               float d
///   4      4     float split      uint32 first prim  float n[0] (unit)  float eps
///   8      4     0                uint32 prim count  float n[1]         0
///   12     4     0                0                  float n[2]         0
///
/// bits: 0-2 kind (FlatBspNodeKind), 3-31 index of the second child (inner
/// nodes; 0 for leaves). The first child follows the node: index + 1 for kd
/// nodes, index + 2 for plane nodes (after the tail). A tail is never entered
/// as a node.
///
/// Plane node: the first child is the closed half-space n·x + d <= 0 (the
/// exact plane's negative side), the second n·x + d >= 0. The float plane is
/// the exact one rounded; `eps` bounds |(n·x + d) − exact(x)| over the node's
/// cell plus the rounding of the constant term, so traversal can be
/// conservative (docs/certified-epsilons.md). kd node: first child is
/// x_axis <= split, second x_axis >= split; split is an exact float.
struct alignas(16) FlatBspNode {
  std::uint32_t bits = std::uint32_t(FlatBspNodeKind::Leaf);  ///< kind | second child << 3
  std::uint32_t w[3] = {0, 0, 0};  ///< payload words (see the layout table)

  /// Largest child index a node can store (29 bits).
  static constexpr std::uint32_t kMaxIndex = (1u << 29) - 1;

  static FlatBspNode make_kd(int axis, float split, std::uint32_t second) {
    FlatBspNode b;
    b.w[0] = std::bit_cast<std::uint32_t>(split);
    b.bits = (second << 3) | std::uint32_t(axis);
    return b;
  }
  static FlatBspNode make_leaf(std::uint32_t offset, std::uint32_t count) {
    FlatBspNode b;
    b.w[0] = offset;
    b.w[1] = count;
    return b;
  }
  /// Head slot of a plane node (the tail must follow it).
  static FlatBspNode make_plane_head(const float normal[3], std::uint32_t second) {
    FlatBspNode b;
    for (int i = 0; i < 3; ++i) b.w[i] = std::bit_cast<std::uint32_t>(normal[i]);
    b.bits = (second << 3) | std::uint32_t(FlatBspNodeKind::Plane);
    return b;
  }
  /// Tail slot of a plane node: offset and certified epsilon.
  static FlatBspNode make_plane_tail(float offset, float epsilon) {
    FlatBspNode b;
    b.bits = std::bit_cast<std::uint32_t>(offset);
    b.w[0] = std::bit_cast<std::uint32_t>(epsilon);
    return b;
  }

  FlatBspNodeKind kind() const { return FlatBspNodeKind(bits & 7u); }
  bool is_leaf() const { return (bits & 7u) == std::uint32_t(FlatBspNodeKind::Leaf); }
  bool is_plane() const { return (bits & 7u) == std::uint32_t(FlatBspNodeKind::Plane); }
  bool is_kd() const { return (bits & 7u) < 3u; }
  /// Slots this node takes (2 for plane nodes).
  std::uint32_t slots() const { return is_plane() ? 2u : 1u; }
  /// Axis of a kd node.
  int axis() const { return int(bits & 7u); }
  /// Split coordinate of a kd node.
  float split() const { return std::bit_cast<float>(w[0]); }
  /// Inner node: index of the second child (the first is index + slots()).
  std::uint32_t second_child() const { return bits >> 3; }
  /// Leaf: first entry in FlatBspTree::prims and number of triangles.
  std::uint32_t prim_offset() const { return w[0]; }
  std::uint32_t prim_count() const { return w[1]; }
  /// Plane head: normal component i.
  float normal(int i) const { return std::bit_cast<float>(w[i]); }
  /// Plane tail: offset d and epsilon.
  float tail_d() const { return std::bit_cast<float>(bits); }
  float tail_eps() const { return std::bit_cast<float>(w[0]); }
  void set_tail_d(float d) { bits = std::bit_cast<std::uint32_t>(d); }
  void set_tail_eps(float e) { w[0] = std::bit_cast<std::uint32_t>(e); }
  void set_split(float s) { w[0] = std::bit_cast<std::uint32_t>(s); }
};
static_assert(sizeof(FlatBspNode) == 16, "FlatBspNode must be 16 bytes");
static_assert(alignof(FlatBspNode) == 16, "FlatBspNode must be 16-byte aligned");

/// The flat BSP tree over one triangle soup. Node 0 is the root; its cell is
/// the box `bounds` (the exact root cell, whose corners are floats).
struct FlatBspTree {
  std::vector<FlatBspNode> nodes;         ///< slots, depth-first, root first
  std::vector<std::uint32_t> prims;   ///< leaf triangle lists (triangle numbers)
  Box3f bounds;                       ///< root cell
  std::uint32_t triangle_count = 0;   ///< triangles of the scene (for checks)

  /// Bytes held by nodes and triangle lists.
  std::size_t memory_bytes() const {
    return nodes.size() * sizeof(FlatBspNode) + prims.size() * sizeof(std::uint32_t);
  }
  /// Structural self-check (Embree's verify()): kinds valid, second child after
  /// the first (no cycles), every node reached once, leaf ranges inside prims,
  /// triangle numbers < triangle_count, planes finite with |n| ≈ 1 and
  /// eps >= 0, kd splits inside the root box. Throws std::logic_error naming
  /// the first problem.
  void validate() const;
};

/// A triangle's corners, copied by tracers in leaf order so a leaf's triangles
/// are contiguous in memory (36 bytes each).
using BspTriangle = LeafTriangle;

/// Figures of a flat BSP tree (reports, `bsprt stats`, docs).
struct FlatBspStats {
  std::size_t nodes = 0;         ///< all nodes
  std::size_t plane_nodes = 0;   ///< inner nodes with a general plane
  std::size_t kd_nodes = 0;      ///< inner nodes with an axis-aligned plane
  std::size_t leaves = 0;        ///< leaves, empty or not
  std::size_t empty_leaves = 0;  ///< leaves with no triangle
  std::size_t references = 0;    ///< triangle references in leaves
  int max_depth = 0;             ///< deepest leaf (root = 0)
  double max_rel_eps = 0.0;      ///< max over plane nodes of eps / max|root box corner|
  std::size_t bytes = 0;         ///< memory_bytes()
};

/// Counts nodes, leaves, references and depth of `tree`.
FlatBspStats flat_bsp_stats(const FlatBspTree& tree);

}  // namespace bsprt
