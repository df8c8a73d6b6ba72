#include "traverse/kd/kd_tree.h"

#include <algorithm>
#include <string>
#include <utility>

#include "geometry/core/check.h"

namespace bsprt {
namespace {

struct StackItem {
  std::uint32_t node;
  int depth;
  Box3f cell;
};

/// Checks one inner node and pushes its children; `seen` guards against nodes
/// reached twice.
void check_inner(const KdTree& tree, const StackItem& it, std::vector<StackItem>& stack) {
  const KdNode& n = tree.nodes[it.node];
  const int k = n.axis();
  const std::uint32_t lower = it.node + 1, upper = n.upper_child();
  BSPRT_CHECK_LT(lower, tree.nodes.size());
  BSPRT_CHECK_LT(upper, tree.nodes.size());
  BSPRT_CHECK_LT(lower, upper);
  // Children inside the parent: the plane lies in the parent's closed cell.
  BSPRT_CHECK_LE(it.cell.lo[k], n.split);
  BSPRT_CHECK_LE(n.split, it.cell.hi[k]);
  Box3f lo_cell = it.cell, hi_cell = it.cell;
  lo_cell.hi[k] = n.split;
  hi_cell.lo[k] = n.split;
  stack.push_back({upper, it.depth + 1, hi_cell});
  stack.push_back({lower, it.depth + 1, lo_cell});
}

}  // namespace

void KdTree::validate() const {
  BSPRT_CHECK(!nodes.empty());
  BSPRT_CHECK(nodes.size() <= std::size_t(KdNode::kMaxOffset) + 1);
  std::vector<std::uint8_t> seen(nodes.size(), 0);
  std::vector<std::uint8_t> prim_used(prims.size(), 0);
  std::vector<StackItem> stack{{0, 0, bounds}};
  std::size_t reached = 0;
  while (!stack.empty()) {
    const StackItem it = stack.back();
    stack.pop_back();
    BSPRT_CHECK_EQ(seen[it.node], 0);  // reached once: a tree, no cycles
    seen[it.node] = 1;
    ++reached;
    const KdNode& n = nodes[it.node];
    if (!n.is_leaf()) {
      check_inner(*this, it, stack);
      continue;
    }
    const std::uint64_t end = std::uint64_t(n.prim_offset()) + n.prim_count();
    BSPRT_CHECK_LE(end, prims.size());
    for (std::uint64_t i = n.prim_offset(); i < end; ++i) {
      BSPRT_CHECK_EQ(prim_used[i], 0);  // leaf lists do not overlap
      prim_used[i] = 1;
      BSPRT_CHECK_LT(prims[i], triangle_count);
    }
  }
  BSPRT_CHECK_EQ(reached, nodes.size());  // every node reached: counts add up
  BSPRT_CHECK(std::find(prim_used.begin(), prim_used.end(), 0) == prim_used.end());
}

KdTreeStats kd_tree_stats(const KdTree& tree) {
  KdTreeStats s;
  s.nodes = tree.nodes.size();
  s.bytes = tree.memory_bytes();
  std::vector<std::pair<std::uint32_t, int>> stack;
  if (!tree.nodes.empty()) stack.push_back({0, 0});
  while (!stack.empty()) {
    const auto [i, depth] = stack.back();
    stack.pop_back();
    const KdNode& n = tree.nodes[i];
    s.max_depth = std::max(s.max_depth, depth);
    if (n.is_leaf()) {
      ++s.leaves;
      s.empty_leaves += n.prim_count() == 0;
      s.references += n.prim_count();
    } else {
      stack.push_back({n.upper_child(), depth + 1});
      stack.push_back({i + 1, depth + 1});
    }
  }
  const std::size_t full = s.leaves - s.empty_leaves;
  s.avg_leaf_size = full ? double(s.references) / double(full) : 0.0;
  return s;
}

}  // namespace bsprt
