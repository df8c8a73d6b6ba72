#pragma once
/// \file bsp_tree.h
/// The exact BSP tree: what the builder decided, stored by input data only
/// (STYLE.md "Two representations, one bridge": this is the rich tree; the float
/// flattening for traversal is a separate step). Nodes refer to a plane table of
/// PlaneDefs (plane.h); leaves to a list of triangle ids. The root cell is the
/// float box root_box(); a node's cell is recomputed exactly on demand from the
/// planes on its path (cell(), for_each_cell()), so nothing rounded is stored.
///
/// Children: left = closed half-space value ≤ 0, right = value ≥ 0 (plane.h).

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "builder/bsp/bsp_config.h"
#include "geometry/core/triangle_soup.h"
#include "robust/cell.h"
#include "robust/plane.h"

namespace bsprt {

/// One node, 12 bytes:
///   offset size field
///   0      4    plane: index into BspTree::planes(), or BspNode::kLeaf
///   4      4    a: inner → left child index;  leaf → first index into triangle_refs()
///   8      4    b: inner → right child index; leaf → triangle count
struct BspNode {
  static constexpr std::uint32_t kLeaf = 0xFFFFFFFFu;
  std::uint32_t plane = kLeaf;
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  bool is_leaf() const { return plane == kLeaf; }
};
static_assert(sizeof(BspNode) == 12, "BspNode is written verbatim into tree files");

/// The exact BSP tree (node 0 is the root; nodes are in depth-first preorder).
class BspTree {
 public:
  BspTree() = default;
  /// Assembles a tree; call validate() to check it.
  BspTree(Box3f root_box, std::vector<PlaneDef> planes, std::vector<BspNode> nodes,
          std::vector<std::uint32_t> triangle_refs, BspMembership membership, bool coplanar_to_both);

  /// The root cell: a box with float corners (exact).
  const Box3f& root_box() const { return root_box_; }
  /// All nodes; node 0 is the root.
  const std::vector<BspNode>& nodes() const { return nodes_; }
  /// The plane table nodes refer to (each plane by its defining input data).
  const std::vector<PlaneDef>& planes() const { return planes_; }
  /// The split plane of inner node `node`.
  PlaneDef plane_of(std::uint32_t node) const { return planes_[nodes_[node].plane]; }
  /// Concatenated leaf triangle lists.
  const std::vector<std::uint32_t>& triangle_refs() const { return refs_; }
  /// The triangles of leaf `node` (ascending ids).
  std::span<const std::uint32_t> leaf_triangles(std::uint32_t node) const;
  /// The membership rule the tree was built with (what a verifier must check).
  BspMembership membership() const { return membership_; }
  /// Whether coplanar triangles were listed on both sides of their plane.
  bool coplanar_to_both() const { return coplanar_to_both_; }
  bool empty() const { return nodes_.empty(); }

  /// Parent of every node (the root's parent is BspNode::kLeaf).
  std::vector<std::uint32_t> parents() const;
  /// Depth of every node (root 0).
  std::vector<std::uint32_t> depths() const;

  /// The exact cell of `node`, recomputed from the root box and its ancestors'
  /// planes (O(depth) exact splits).
  Cell cell(const TriangleSoup& soup, std::uint32_t node, ExactStats* stats = nullptr) const;
  /// Calls `visit(node, cell)` for every node, parents before children, splitting
  /// each cell once (O(nodes) exact splits). Throws std::logic_error if a stored
  /// plane does not cut its node's cell.
  void for_each_cell(const TriangleSoup& soup,
                     const std::function<void(std::uint32_t, const Cell&)>& visit,
                     ExactStats* stats = nullptr) const;

  /// Structural check (STYLE.md "Every structure can check itself"): every node
  /// reachable exactly once from the root, child indices and plane indices in
  /// range, leaf ranges inside triangle_refs() and tiling it, triangle ids below
  /// `triangle_count`, sorted and unique per leaf, planes in range for `soup`
  /// when given. Throws std::logic_error naming the first problem.
  void validate(std::size_t triangle_count, const TriangleSoup* soup = nullptr) const;

 private:
  Box3f root_box_;
  std::vector<PlaneDef> planes_;
  std::vector<BspNode> nodes_;
  std::vector<std::uint32_t> refs_;
  BspMembership membership_ = BspMembership::Closed;
  bool coplanar_to_both_ = true;
};

}  // namespace bsprt
