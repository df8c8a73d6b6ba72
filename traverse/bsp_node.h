#pragma once
/// \file bsp_node.h
/// The flat float BSP tree that traversal reads (Ize, Wald, Parker, "Ray
/// Tracing with the BSP Tree", RT 2008, §5): 32-byte nodes in depth-first order
/// (first child adjacent), general planes with a *certified* slab bound, kd
/// nodes for axis-aligned splits (the paper's "kd-tree traversal for
/// axis-aligned splits": no dot product), and one array of leaf triangle lists.
/// Made once from the exact tree by builder/bsp_flatten.h; traced by
/// traverse/bsp_traverse.h. No CGAL here.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/vec3.h"

namespace bsprt {

/// Deepest flat tree the traversal stacks hold (the exact builder's default
/// max_depth is 64).
inline constexpr int kBspMaxDepth = 128;

/// What a FlatBspNode is. Values 0..2 are kd nodes on that axis.
enum class FlatBspNodeKind : std::uint32_t { KdX = 0, KdY = 1, KdZ = 2, Plane = 3, Leaf = 4 };

/// One node of the flat BSP tree, 32 bytes, two per cache line. Byte layout
/// (little-endian):
///
///   offset size  Plane node            kd node              leaf
///   0      12    float n[3] (unit)     n[0] = float split   unused (0)
///   12     4     float d               unused (0)           unused (0)
///   16     4     float eps (certified) unused (0)           unused (0)
///   20     4     bits 0-2: kind (FlatBspNodeKind); bits 3-31: index of the second
///                child (inner nodes; the first child is the next node) / 0
///   24     4     unused (0)            unused (0)           uint32 first entry in prims
///   28     4     unused (0)            unused (0)           uint32 triangle count
///
/// Plane node: the first child is the closed half-space n·x + d <= 0 (the
/// exact plane's negative side), the second n·x + d >= 0. The float plane is
/// the exact one rounded; `eps` bounds |(n·x + d) − exact(x)| over the node's
/// cell plus the rounding of the constant term, so traversal can be
/// conservative (docs/certified-epsilons.md). kd node: first child is
/// x_axis <= split, second x_axis >= split; split is an exact float.
struct alignas(32) FlatBspNode {
  float n[3] = {0.0f, 0.0f, 0.0f};  ///< plane normal; kd: n[0] is the split
  float d = 0.0f;                   ///< plane offset
  float eps = 0.0f;                 ///< certified slab half-width at t = 0 (see docs)
  std::uint32_t bits = std::uint32_t(FlatBspNodeKind::Leaf);  ///< kind | second child << 3
  std::uint32_t prim_offset = 0;    ///< leaf: first entry in FlatBspTree::prims
  std::uint32_t prim_count = 0;     ///< leaf: number of triangles

  /// Largest child index a node can store (29 bits).
  static constexpr std::uint32_t kMaxIndex = (1u << 29) - 1;

  static FlatBspNode make_plane(const float normal[3], float offset, float epsilon,
                            std::uint32_t second) {
    FlatBspNode b;
    b.n[0] = normal[0], b.n[1] = normal[1], b.n[2] = normal[2];
    b.d = offset;
    b.eps = epsilon;
    b.bits = (second << 3) | std::uint32_t(FlatBspNodeKind::Plane);
    return b;
  }
  static FlatBspNode make_kd(int axis, float split, std::uint32_t second) {
    FlatBspNode b;
    b.n[0] = split;
    b.bits = (second << 3) | std::uint32_t(axis);
    return b;
  }
  static FlatBspNode make_leaf(std::uint32_t offset, std::uint32_t count) {
    FlatBspNode b;
    b.prim_offset = offset;
    b.prim_count = count;
    return b;
  }

  FlatBspNodeKind kind() const { return FlatBspNodeKind(bits & 7u); }
  bool is_leaf() const { return (bits & 7u) == std::uint32_t(FlatBspNodeKind::Leaf); }
  bool is_plane() const { return (bits & 7u) == std::uint32_t(FlatBspNodeKind::Plane); }
  bool is_kd() const { return (bits & 7u) < 3u; }
  /// Axis of a kd node.
  int axis() const { return int(bits & 7u); }
  /// Split coordinate of a kd node.
  float split() const { return n[0]; }
  /// Inner node: index of the second child (the first is this index + 1).
  std::uint32_t second_child() const { return bits >> 3; }
};
static_assert(sizeof(FlatBspNode) == 32, "FlatBspNode must be 32 bytes");
static_assert(alignof(FlatBspNode) == 32, "FlatBspNode must be 32-byte aligned");

/// The flat BSP tree over one triangle soup. Node 0 is the root; its cell is
/// the box `bounds` (the exact root cell, whose corners are floats).
struct FlatBspTree {
  std::vector<FlatBspNode> nodes;         ///< depth-first, root first
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
struct BspTriangle {
  Vec3f v[3];
};

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
