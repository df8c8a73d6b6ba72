/// \file bsp_tree.cpp
/// BspTree accessors, exact cell recomputation and validate().
#include "builder/bsp/bsp_tree.h"

#include <algorithm>
#include <string>
#include <utility>

#include "geometry/core/check.h"

namespace bsprt {

namespace {
[[noreturn]] void invalid(const std::string& what) { throw std::logic_error("BspTree::validate: " + what); }
}  // namespace

BspTree::BspTree(Box3f root_box, std::vector<PlaneDef> planes, std::vector<BspNode> nodes,
                 std::vector<std::uint32_t> triangle_refs, BspMembership membership,
                 bool coplanar_to_both)
    : root_box_(root_box),
      planes_(std::move(planes)),
      nodes_(std::move(nodes)),
      refs_(std::move(triangle_refs)),
      membership_(membership),
      coplanar_to_both_(coplanar_to_both) {}

std::span<const std::uint32_t> BspTree::leaf_triangles(std::uint32_t node) const {
  const BspNode& n = nodes_[node];
  BSPRT_CHECK(n.is_leaf());
  return std::span<const std::uint32_t>(refs_).subspan(n.a, n.b);
}

std::vector<std::uint32_t> BspTree::parents() const {
  std::vector<std::uint32_t> p(nodes_.size(), BspNode::kLeaf);
  for (std::uint32_t i = 0; i < nodes_.size(); ++i)
    if (!nodes_[i].is_leaf()) p[nodes_[i].a] = p[nodes_[i].b] = i;
  return p;
}

std::vector<std::uint32_t> BspTree::depths() const {
  std::vector<std::uint32_t> d(nodes_.size(), 0);
  std::vector<std::uint32_t> stack;
  if (!nodes_.empty()) stack.push_back(0);
  while (!stack.empty()) {
    const std::uint32_t i = stack.back();
    stack.pop_back();
    if (nodes_[i].is_leaf()) continue;
    d[nodes_[i].a] = d[nodes_[i].b] = d[i] + 1;
    stack.push_back(nodes_[i].a);
    stack.push_back(nodes_[i].b);
  }
  return d;
}

Cell BspTree::cell(const TriangleSoup& soup, std::uint32_t node, ExactStats* stats) const {
  BSPRT_CHECK_LT(node, nodes_.size());
  const std::vector<std::uint32_t> par = parents();
  std::vector<std::uint32_t> path;  // node, parent, ..., root
  for (std::uint32_t i = node; i != BspNode::kLeaf; i = par[i]) path.push_back(i);
  ExactStats local;
  RoundingGuard g;
  Cell c = Cell::box(root_box_);
  for (std::size_t k = path.size() - 1; k > 0; --k) {
    const std::uint32_t parent = path[k], child = path[k - 1];
    Cell l, r;
    const PreparedPlane pp = prepare_plane(g, soup, plane_of(parent));
    BSPRT_CHECK(c.split(g, soup, pp, l, r, local));
    c = std::move(nodes_[parent].a == child ? l : r);
  }
  if (stats) stats->add(local);
  return c;
}

void BspTree::for_each_cell(const TriangleSoup& soup,
                            const std::function<void(std::uint32_t, const Cell&)>& visit,
                            ExactStats* stats) const {
  if (nodes_.empty()) return;
  ExactStats local;
  std::vector<std::pair<std::uint32_t, Cell>> stack;
  stack.emplace_back(0, Cell::box(root_box_));
  while (!stack.empty()) {
    auto [i, c] = std::move(stack.back());
    stack.pop_back();
    visit(i, c);
    const BspNode& n = nodes_[i];
    if (n.is_leaf()) continue;
    Cell l, r;
    {
      RoundingGuard g;
      const PreparedPlane pp = prepare_plane(g, soup, planes_[n.plane]);
      if (!c.split(g, soup, pp, l, r, local))
        throw std::logic_error("BspTree: plane of node " + std::to_string(i) + " does not cut its cell");
    }
    stack.emplace_back(n.b, std::move(r));
    stack.emplace_back(n.a, std::move(l));
  }
  if (stats) stats->add(local);
}

void BspTree::validate(std::size_t triangle_count, const TriangleSoup* soup) const {
  if (nodes_.empty()) invalid("no nodes");
  if (!(root_box_.lo.x < root_box_.hi.x && root_box_.lo.y < root_box_.hi.y && root_box_.lo.z < root_box_.hi.z))
    invalid("root box is empty or flat");
  const std::size_t n = nodes_.size();
  std::vector<std::uint8_t> seen(n, 0);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges;
  std::vector<std::uint32_t> stack{0};
  std::size_t reached = 0;
  while (!stack.empty()) {
    const std::uint32_t i = stack.back();
    stack.pop_back();
    if (i >= n) invalid("child index " + std::to_string(i) + " out of range");
    if (seen[i]++) invalid("node " + std::to_string(i) + " reached twice");
    ++reached;
    const BspNode& nd = nodes_[i];
    if (nd.is_leaf()) {
      ranges.emplace_back(nd.a, nd.b);
      continue;
    }
    if (nd.plane >= planes_.size()) invalid("plane index out of range at node " + std::to_string(i));
    if (soup && !plane_in_range(*soup, planes_[nd.plane])) invalid("plane out of range at node " + std::to_string(i));
    stack.push_back(nd.a);
    stack.push_back(nd.b);
  }
  if (reached != n) invalid(std::to_string(n - reached) + " nodes unreachable from the root");
  std::sort(ranges.begin(), ranges.end());
  std::uint64_t next = 0;
  for (const auto& [first, count] : ranges) {
    if (first != next) invalid("leaf triangle ranges do not tile the reference list");
    next = std::uint64_t(first) + count;
    if (next > refs_.size()) invalid("leaf triangle range past the reference list");
    for (std::uint32_t k = first; k < first + count; ++k) {
      if (refs_[k] >= triangle_count) invalid("triangle id " + std::to_string(refs_[k]) + " out of range");
      if (k > first && refs_[k] <= refs_[k - 1]) invalid("leaf triangle list not sorted/unique");
    }
  }
  if (next != refs_.size()) invalid("leaf triangle ranges do not cover the reference list");
}

}  // namespace bsprt
