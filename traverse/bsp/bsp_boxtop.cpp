/// \file bsp_boxtop.cpp
/// Subtree boxes for the box top (bsp_boxtop.h). Pure float min/max: exact.
#include "traverse/bsp/bsp_boxtop.h"

#include <algorithm>
#include <limits>

namespace bsprt {
namespace {

/// Distinct triangles (by number) of a subtree's leaf lists, with an early exit.
struct Distinct {
  const CompactBspTree& tree;
  std::span<const std::uint32_t> prims;
  std::uint32_t limit;                 ///< stop once more than this many are found
  std::vector<std::uint32_t> entries;  ///< first entry of each distinct triangle

  /// False once more than `limit` distinct triangles are found.
  bool collect(std::uint32_t i) {
    const CompactBspSlot& n = tree.slots[i];
    if (n.is_leaf()) {
      for (std::uint32_t j = n.prim_offset(), e = j + n.prim_count(); j < e; ++j) {
        bool seen = false;
        for (const std::uint32_t k : entries) seen = seen || prims[k] == prims[j];
        if (seen) continue;
        if (entries.size() == limit) return false;
        entries.push_back(j);
      }
      return true;
    }
    if (!n.first_empty() && !collect(i + n.slots())) return false;
    return n.second_empty() || collect(n.second_child());
  }
};

struct Cutter {
  const CompactBspTree& tree;
  std::span<const BspTriangle> triangles;
  std::uint32_t max_slots;
  std::span<const std::uint32_t> prims;
  std::uint32_t max_triangles;
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
    if (max_triangles > 0) {
      Distinct d{tree, prims, max_triangles, {}};
      if (d.collect(i)) {
        Box3f box;
        gather(i, cell, box);
        if (!box.empty()) out.push_back({i, box, std::uint32_t(d.entries.size())});
        return;
      }
    }
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
                                             const Box3f& bounds, std::uint32_t max_slots,
                                             std::span<const std::uint32_t> prims, std::uint32_t max_triangles) {
  if (tree.slots.empty() || bounds.empty()) return {};
  if (prims.size() != triangles.size()) max_triangles = 0;  // no triangle numbers: the size rule only
  Cutter c{tree, triangles, max_slots, prims, max_triangles, std::vector<std::uint32_t>(tree.slots.size(), 0), {}};
  c.measure(0);
  c.cut(0, bounds);
  return std::move(c.out);
}

std::vector<std::uint32_t> bsp_subtree_entries(const CompactBspTree& tree, std::span<const std::uint32_t> prims,
                                               std::uint32_t slot) {
  Distinct d{tree, prims, std::numeric_limits<std::uint32_t>::max(), {}};
  d.collect(slot);
  return std::move(d.entries);
}

}  // namespace bsprt
