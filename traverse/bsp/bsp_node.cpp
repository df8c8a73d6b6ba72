/// \file bsp_node.cpp
/// Self-check and figures of the flat BSP tree.
#include "traverse/bsp/bsp_node.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "geometry/core/check.h"

namespace bsprt {
namespace {

/// Checks a plane node (head and tail): finite, ‖n‖₁ within the bound the
/// traversal's error coefficients assume (kNormL1Max = 1.7321), ‖n‖₂ ≈ 1.
void check_plane(const FlatBspNode& head, const FlatBspNode& tail) {
  const double n[3] = {head.normal(0), head.normal(1), head.normal(2)};
  const double l1 = std::fabs(n[0]) + std::fabs(n[1]) + std::fabs(n[2]);
  const double l2 = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  BSPRT_CHECK(std::isfinite(tail.tail_d()));
  BSPRT_CHECK(std::isfinite(tail.tail_eps()));
  BSPRT_CHECK_LE(l1, 1.73206);  // √3 + 1e-5 < kNormL1Max (bsp_kernel.h)
  BSPRT_CHECK_LE(std::fabs(l2 - 1.0), 1e-6);
  BSPRT_CHECK_LE(0.0f, tail.tail_eps());
}

}  // namespace

void FlatBspTree::validate() const {
  BSPRT_CHECK(!nodes.empty());
  BSPRT_CHECK_LE(nodes.size(), std::size_t(FlatBspNode::kMaxIndex) + 1);
  std::vector<std::uint8_t> seen(nodes.size(), 0);
  std::vector<std::uint8_t> prim_used(prims.size(), 0);
  std::vector<std::uint32_t> stack{0};
  std::size_t reached = 0;
  while (!stack.empty()) {
    const std::uint32_t i = stack.back();
    stack.pop_back();
    BSPRT_CHECK_EQ(seen[i], 0);  // reached once: a tree, no cycles
    seen[i] = 1;
    ++reached;
    const FlatBspNode& n = nodes[i];
    BSPRT_CHECK_LE(n.bits & 7u, 4u);
    if (n.is_leaf()) {
      const std::uint64_t end = std::uint64_t(n.prim_offset()) + n.prim_count();
      BSPRT_CHECK_LE(end, prims.size());
      for (std::uint64_t k = n.prim_offset(); k < end; ++k) {
        BSPRT_CHECK_EQ(prim_used[k], 0);  // leaf lists do not overlap
        prim_used[k] = 1;
        BSPRT_CHECK_LT(prims[k], triangle_count);
      }
      continue;
    }
    const std::uint32_t first = i + n.slots(), second = n.second_child();
    BSPRT_CHECK_LT(first, nodes.size());
    BSPRT_CHECK_LT(second, nodes.size());
    BSPRT_CHECK_LT(first, second);
    if (n.is_plane()) {
      check_plane(n, nodes[i + 1]);
      BSPRT_CHECK_EQ(seen[i + 1], 0);  // the tail is never a node
      seen[i + 1] = 1;
      ++reached;
    } else {
      BSPRT_CHECK(std::isfinite(n.split()));
      BSPRT_CHECK_LE(bounds.lo[n.axis()], n.split());
      BSPRT_CHECK_LE(n.split(), bounds.hi[n.axis()]);
    }
    stack.push_back(second);
    stack.push_back(first);
  }
  BSPRT_CHECK_EQ(reached, nodes.size());  // every slot reached once: counts add up
  BSPRT_CHECK(std::find(prim_used.begin(), prim_used.end(), 0) == prim_used.end());
}

FlatBspStats flat_bsp_stats(const FlatBspTree& tree) {
  FlatBspStats s;
  s.bytes = tree.memory_bytes();
  double scale = 0.0;
  for (int k = 0; k < 3; ++k)
    scale = std::max({scale, std::fabs(double(tree.bounds.lo[k])), std::fabs(double(tree.bounds.hi[k]))});
  std::vector<std::pair<std::uint32_t, int>> stack;
  if (!tree.nodes.empty()) stack.push_back({0, 0});
  while (!stack.empty()) {
    const auto [i, depth] = stack.back();
    stack.pop_back();
    const FlatBspNode& n = tree.nodes[i];
    s.max_depth = std::max(s.max_depth, depth);
    if (n.is_leaf()) {
      ++s.leaves;
      s.empty_leaves += n.prim_count() == 0;
      s.references += n.prim_count();
      continue;
    }
    if (n.is_plane()) {
      ++s.plane_nodes;
      if (scale > 0) s.max_rel_eps = std::max(s.max_rel_eps, double(tree.nodes[i + 1].tail_eps()) / scale);
    } else {
      ++s.kd_nodes;
    }
    stack.push_back({n.second_child(), depth + 1});
    stack.push_back({i + n.slots(), depth + 1});
  }
  s.nodes = s.leaves + s.plane_nodes + s.kd_nodes;
  return s;
}

}  // namespace bsprt
