#pragma once
/// \file bvh8_node.h
/// A plain 8-wide bounding-volume hierarchy over triangles (issue #26, step
/// one): the box kernel of bvh8_kernel.inl on the same kind of tree Embree
/// traces, so the kernel can be compared with Embree's apart from the tree.
///
/// Node layout (224 bytes, 32-byte aligned; Embree's AABBNode8 idea with
/// 32-bit references): six rows of eight floats, lo_x hi_x lo_y hi_y lo_z
/// hi_z, then eight child references. A ray picks its near and far row per
/// axis once from the signs of its direction (bvh8_kernel.inl), so no node
/// test branches on the direction. An unused slot has the empty box
/// (lo = +inf, hi = -inf), which no ray enters, and reference 0.
///
/// Child reference (32 bits): the low 4 bits are 0 for an inner node, whose
/// index is ref >> 4, or the number n of triangles (1..4) of a leaf, whose
/// first entry in the leaf lists is ref >> 4. Node 0 is the root and never a
/// child, so reference 0 in a slot means "empty". Low bits 15 (kSubtree) mark
/// a BSP subtree under the box (issue #26 step two, bsp_traverse.h's
/// set_bvh8_top): ref >> 4 indexes Bvh8Tree::subtrees, and the kernel hands
/// the ray to the tracer's subtree callback (bvh8_kernel.h).
///
/// A leaf's triangles are stored twice. For the float kernel, which tests
/// them at once in four lanes (as Embree tests its Triangle4 leaves), in SoA
/// form without padding: nine rows of n floats (corner c, axis k at row
/// 3c + k) from leaf_soa[10 first], then a tenth row of the n triangle
/// numbers (Bvh8Tree::encode_prim), so that a hit reads its number from the
/// lines the test has loaded; a row is loaded as four floats, lanes past n masked off
/// (leaf_soa ends with three spare floats). For the exact leaf test's
/// interface, as lists in leaf order: prims and triangles from first.

#include <bit>
#include <cstdint>
#include <span>
#include <vector>

#include "bsprt/vec3.h"
#include "traverse/leaf_intersector.h"

namespace bsprt {

/// One node: boxes of up to eight children (SoA rows) and their references.
struct alignas(32) Bvh8Node {
  /// box[2k][i] = lower bound on axis k of child i, box[2k + 1][i] = upper bound.
  float box[6][8];
  std::uint32_t child[8];  ///< references (see the file comment); 0 = empty slot

  static constexpr std::uint32_t kLeafMask = 0xfu;
  static constexpr std::uint32_t kMaxLeafSize = 4;
  static constexpr std::uint32_t kSubtree = 0xfu;  ///< count() of a BSP subtree reference
  static bool is_leaf(std::uint32_t ref) { return (ref & kLeafMask) != 0; }
  static std::uint32_t index(std::uint32_t ref) { return ref >> 4; }
  static std::uint32_t count(std::uint32_t ref) { return ref & kLeafMask; }
  static std::uint32_t inner_ref(std::uint32_t node) { return node << 4; }
  static std::uint32_t leaf_ref(std::uint32_t first, std::uint32_t n) { return (first << 4) | n; }
  static std::uint32_t subtree_ref(std::uint32_t subtree) { return (subtree << 4) | kSubtree; }
  /// A node whose eight slots are empty.
  static Bvh8Node empty();
  /// Sets slot i to `ref` with box b.
  void set(int i, std::uint32_t ref, const Box3f& b);
  /// Box of slot i.
  Box3f child_box(int i) const;
};
static_assert(sizeof(Bvh8Node) == 224, "Bvh8Node: 6 x 8 floats + 8 references");
static_assert(alignof(Bvh8Node) == 32, "Bvh8Node rows are loaded as aligned 32-byte vectors");

/// A BSP subtree under a leaf slot of a BVH8 top: its root slot in the
/// compact BSP tree and its certified box (bsp_boxtop.h, BspSubtreeBox).
struct Bvh8Subtree {
  std::uint32_t slot;
  Box3f box;
};

/// The tree: nodes (0 = root, always an inner node), and the leaf lists in
/// leaf order: corners in SoA rows, triangle numbers, corners as triangles.
///
/// A top over a BSP tree (`over_bsp`) has pieces of the BSP's leaf cells as
/// leaves: a leaf cell of at most four triangles becomes a triangle leaf,
/// anything else a subtree reference. Such a leaf's box is the certified box
/// of its cell's piece (bsp_boxtop.h), so a triangle may reach outside it and
/// be listed in several leaves; the BSP's certificate, not the leaf boxes,
/// says that no hit is lost (docs/bvh8.md, "BSP subtrees below").
struct Bvh8Tree {
  std::vector<Bvh8Node> nodes;
  /// Floats per leaf entry in leaf_soa: nine corner coordinates and the triangle number.
  static constexpr std::uint32_t kSoaFloats = 10;
  /// The number row holds triangle p as the float with bits p + 0x3f800000
  /// (1.0 for triangle 0, below 4.0 up to 2^24 triangles): the four-float
  /// loads of row 8 read it into lanes that are masked off but still
  /// computed, and plain bits would be subnormal there, which some CPUs
  /// slow down for (a microcode assist on every such product).
  static float encode_prim(std::uint32_t p) { return std::bit_cast<float>(p + 0x3f800000u); }
  static std::uint32_t decode_prim(float f) { return std::bit_cast<std::uint32_t>(f) - 0x3f800000u; }
  std::vector<float> leaf_soa;  ///< kSoaFloats per leaf entry (see the file comment), then 3 spare
  std::vector<std::uint32_t> prims;
  std::vector<LeafTriangle> triangles;  ///< corners of prims[i] at triangles[i]
  std::uint32_t depth = 0;              ///< levels of inner nodes (root = 1)
  std::uint32_t scene_triangles = 0;    ///< triangles of the scene it was built for
  std::uint32_t left_out = 0;           ///< degenerate (or non-finite) triangles, in no leaf: no mode hits them
  std::vector<Bvh8Subtree> subtrees;    ///< BSP subtrees (kSubtree references), over_bsp only
  bool over_bsp = false;                ///< leaves are pieces of BSP cells (see above)
  std::uint32_t pieces = 0;             ///< over_bsp: leaf cells and subtrees it was built from

  /// Checks the invariants; throws std::logic_error naming the broken one:
  /// references in range, every node reached once, each child's box holds
  /// its subtree's boxes and a leaf's box its triangles' corners, SoA rows
  /// equal to the lists, every triangle in at most one leaf and exactly
  /// `left_out` in none. Over a BSP: the same, except that leaf boxes need
  /// not hold their triangles and triangles may repeat; instead every subtree
  /// is referenced once, and leaves plus subtrees number `pieces`.
  void validate() const;
  std::size_t memory_bytes() const {
    return nodes.size() * sizeof(Bvh8Node) + leaf_soa.size() * sizeof(float) +
           prims.size() * sizeof(std::uint32_t) + triangles.size() * sizeof(LeafTriangle) +
           subtrees.size() * sizeof(Bvh8Subtree);
  }
};

}  // namespace bsprt
