/// \file bsp_boxtop.cpp
/// Subtree boxes for the box top (bsp_boxtop.h). Pure float min/max: exact.
#include "traverse/bsp/bsp_boxtop.h"

#include <algorithm>

namespace bsprt {
namespace {

struct Cutter {
  const CompactBspTree& tree;
  std::span<const BspTriangle> triangles;
  std::uint32_t max_slots;
  std::vector<std::uint32_t> size;  ///< slots of the subtree at each node slot
  std::vector<BspSubtreeBox> out;

  std::uint32_t first(std::uint32_t i) const { return i + tree.slots[i].slots(); }

  std::uint32_t measure(std::uint32_t i) {
    const CompactBspSlot& n = tree.slots[i];
    std::uint32_t s = n.slots();
    if (!n.is_leaf()) {
      if (!n.first_empty()) s += measure(first(i));
      if (!n.second_empty()) s += measure(n.second_child());
    }
    return size[i] = s;
  }

  /// The two child boxes of node i inside `cell` (kd: split; plane: unchanged).
  static void split_box(const CompactBspSlot& n, const Box3f& cell, Box3f& lo_box, Box3f& hi_box) {
    lo_box = hi_box = cell;
    if (n.is_plane()) return;
    const int k = n.axis();
    lo_box.hi[k] = std::min(cell.hi[k], n.split());
    hi_box.lo[k] = std::max(cell.lo[k], n.split());
  }

  /// Adds to `box` the points where leaf triangles of subtree i meet their kd boxes.
  void gather(std::uint32_t i, const Box3f& cell, Box3f& box) const {
    const CompactBspSlot& n = tree.slots[i];
    if (n.is_leaf()) {
      Box3f tris;
      for (std::uint32_t j = n.prim_offset(), e = j + n.prim_count(); j < e; ++j)
        for (const Vec3f& p : triangles[j].v) tris.extend(p);  // NaN corners drop out of min/max
      Box3f clipped;
      clipped.lo = max(tris.lo, cell.lo);
      clipped.hi = min(tris.hi, cell.hi);
      if (!clipped.empty()) box.extend(clipped);
      return;
    }
    Box3f a, b;
    split_box(n, cell, a, b);
    if (!n.first_empty()) gather(first(i), a, box);
    if (!n.second_empty()) gather(n.second_child(), b, box);
  }

  void cut(std::uint32_t i, const Box3f& cell) {
    const CompactBspSlot& n = tree.slots[i];
    if (n.is_leaf() || size[i] <= max_slots) {
      Box3f box;
      gather(i, cell, box);
      if (!box.empty()) out.push_back({i, box});
      return;
    }
    Box3f a, b;
    split_box(n, cell, a, b);
    if (!n.first_empty()) cut(first(i), a);
    if (!n.second_empty()) cut(n.second_child(), b);
  }
};

}  // namespace

std::vector<BspSubtreeBox> bsp_subtree_boxes(const CompactBspTree& tree, std::span<const BspTriangle> triangles,
                                             const Box3f& bounds, std::uint32_t max_slots) {
  if (tree.slots.empty() || bounds.empty()) return {};
  Cutter c{tree, triangles, max_slots, std::vector<std::uint32_t>(tree.slots.size(), 0), {}};
  c.measure(0);
  c.cut(0, bounds);
  return std::move(c.out);
}

}  // namespace bsprt
