#pragma once
/// \file bsp_compact.h
/// The traversal's own layout of the flat BSP tree. BspTracer makes it once
/// from the FlatBspTree (the certified form that tree files store and
/// `bsprt verify` checks, bsp_node.h), copying every float bit for bit; only
/// the layout changes, so the certificate carries over:
///
///  - kd nodes and leaves take one 8-byte slot (the size of a kd-tree node,
///    kd_tree.h), plane nodes three (24 bytes): twice as many kd nodes per
///    cache line as the 16-byte FlatBspNode;
///  - a subtree that lists no triangle (an empty leaf, or splits over empty
///    leaves only) is not stored: its parent carries an "empty" bit for that
///    child, so traversal neither fetches nor stacks it. Visiting it could not
///    find a hit (README: leave out what the scene does not need).
///
/// Slot layout (two little-endian uint32 words, `head` and `word`):
///
///   head bits 0-2  kind (FlatBspNodeKind: 0-2 kd axis, 3 plane, 4 leaf)
///   head bit 3     inner: the first child is empty (not stored)
///   head bit 4     inner: the second child is empty (not stored)
///   head bits 5-31 inner: slot of the second child (0 when empty);
///                  leaf: number of triangles (>= 1, except a root leaf of a
///                  tree without triangles)
///   word           kd: split (float); leaf: first entry of the prims list;
///                  plane: n[0] (float)
///   plane slot +1  n[1], n[2];  plane slot +2  d, eps (floats)
///
/// A stored first child follows its parent's last slot. No CGAL here.

#include <bit>
#include <cstdint>
#include <vector>

#include "traverse/bsp/bsp_node.h"

namespace bsprt {

/// One 8-byte slot of a CompactBspTree (see the layout above).
struct alignas(8) CompactBspSlot {
  std::uint32_t head = std::uint32_t(FlatBspNodeKind::Leaf);
  std::uint32_t word = 0;

  static constexpr std::uint32_t kFirstEmpty = 1u << 3;
  static constexpr std::uint32_t kSecondEmpty = 1u << 4;
  static constexpr int kShift = 5;
  /// Largest slot index or leaf size a head can hold (27 bits).
  static constexpr std::uint32_t kMaxIndex = (1u << 27) - 1;

  std::uint32_t kind_bits() const { return head & 7u; }
  bool is_leaf() const { return kind_bits() == std::uint32_t(FlatBspNodeKind::Leaf); }
  bool is_plane() const { return kind_bits() == std::uint32_t(FlatBspNodeKind::Plane); }
  /// Slots of this node (3 for planes).
  std::uint32_t slots() const { return is_plane() ? 3u : 1u; }
  int axis() const { return int(kind_bits()); }
  float split() const { return std::bit_cast<float>(word); }
  bool first_empty() const { return (head & kFirstEmpty) != 0; }
  bool second_empty() const { return (head & kSecondEmpty) != 0; }
  std::uint32_t second_child() const { return head >> kShift; }
  std::uint32_t prim_count() const { return head >> kShift; }
  std::uint32_t prim_offset() const { return word; }
  /// Plane node (this slot and the two after it): normal component k, offset d, epsilon.
  float plane_normal(int k) const {
    return std::bit_cast<float>(k == 0 ? word : k == 1 ? this[1].head : this[1].word);
  }
  float plane_d() const { return std::bit_cast<float>(this[2].head); }
  float plane_eps() const { return std::bit_cast<float>(this[2].word); }
};
static_assert(sizeof(CompactBspSlot) == 8, "CompactBspSlot must be 8 bytes");

/// The traversal layout of one flat BSP tree. Node 0 is the root.
struct CompactBspTree {
  std::vector<CompactBspSlot> slots;
};

/// The compact layout of `flat` (validated by the caller). Every kd split,
/// plane normal, offset and epsilon is copied bit for bit; leaves keep their
/// range of `flat.prims`. Throws UsageError when the tree needs more than
/// CompactBspSlot::kMaxIndex slots or a leaf lists more triangles.
CompactBspTree compact_bsp(const FlatBspTree& flat);

}  // namespace bsprt
