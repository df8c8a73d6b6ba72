#pragma once
/// \file bsp_boxtop.h
/// A box top over the BSP tree: a 4-wide bounding-box hierarchy whose leaves
/// are BSP subtrees. Random rays spend most of their BSP steps in the tree's
/// top, deciding one empty slab at a time; a box test rejects a whole subtree
/// in one vector step (Embree's strength), and the BSP below keeps its cells
/// (its strength: few triangle tests).
///
/// Certificate (docs/certified-epsilons.md §10): the box of a subtree is the
/// union, over its leaves, of the box of the leaf's triangles intersected with
/// the box that the kd splits above the leaf cut out of the root cell. Every
/// one of these numbers is a float of the scene or of the tree, and min/max are
/// exact, so the box holds every point where a leaf's triangle meets its cell.
/// The ray/box test widens its slab crossings like the root clip (§3), so a
/// ray whose exact path meets a leaf triangle inside the leaf's cell enters the
/// subtree's box with an interval holding that point; inside, the BSP steps are
/// the certified ones, whose epsilons hold at every point of a cell. No CGAL.

#include <cstdint>
#include <span>
#include <vector>

#include "bsprt/vec3.h"
#include "traverse/bsp/bsp_compact.h"
#include "traverse/bsp/bsp_node.h"

namespace bsprt {

class BspTracer;

/// One node of the box top: four children, boxes in SoA order.
struct alignas(16) BoxTopNode {
  float lo[3][4];              ///< lo[axis][child]
  float hi[3][4];              ///< hi[axis][child]
  std::uint32_t child[4];      ///< kNone, an inner node index, or kSubtree | slot of a BSP subtree root

  static constexpr std::uint32_t kNone = 0xffffffffu;
  static constexpr std::uint32_t kSubtree = 0x80000000u;
};
static_assert(sizeof(BoxTopNode) == 112, "BoxTopNode must be 112 bytes");

/// The box top; node 0 is the root. Empty: no top (plain BSP traversal).
struct BoxTop {
  std::vector<BoxTopNode> nodes;
  std::uint32_t subtrees = 0;  ///< BSP subtrees under it
};

/// A BSP subtree and its certified box.
struct BspSubtreeBox {
  std::uint32_t slot;  ///< root slot of the subtree in the compact tree
  Box3f box;           ///< holds every point where a listed triangle meets a leaf cell of the subtree
  /// Cut by the small-subtree rule (bsp_subtree_boxes' max_triangles): the
  /// number of distinct triangles its leaves list; 0 when cut by size.
  std::uint32_t triangles = 0;
};

/// Cuts the compact tree into the largest subtrees of at most `max_slots`
/// slots (a leaf root gives one subtree) and computes their boxes (see the
/// file comment). `triangles[i]` holds the corners of leaf-list entry i.
/// Subtrees whose box is empty (no listed triangle meets its kd box) are left
/// out: no ray can hit anything in them.
///
/// With `max_triangles` > 0 (and `prims`, the leaf lists' triangle numbers),
/// a subtree whose leaves list at most that many distinct triangles is cut
/// there too, however many slots it has, and records their number: a caller
/// may test them directly instead of walking the subtree (the BVH8 top does).
std::vector<BspSubtreeBox> bsp_subtree_boxes(const CompactBspTree& tree, std::span<const BspTriangle> triangles,
                                             const Box3f& bounds, std::uint32_t max_slots,
                                             std::span<const std::uint32_t> prims = {},
                                             std::uint32_t max_triangles = 0);

/// The leaf-list entries of the subtree at `slot`, the first entry of each
/// distinct triangle (by `prims`), in depth-first order.
std::vector<std::uint32_t> bsp_subtree_entries(const CompactBspTree& tree, std::span<const std::uint32_t> prims,
                                               std::uint32_t slot);

}  // namespace bsprt
