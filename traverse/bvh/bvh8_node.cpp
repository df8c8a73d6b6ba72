/// \file bvh8_node.cpp
/// Bvh8Node helpers and Bvh8Tree::validate.
#include "traverse/bvh/bvh8_node.h"

#include <limits>
#include <stdexcept>
#include <string>

namespace bsprt {

Bvh8Node Bvh8Node::empty() {
  Bvh8Node n;
  const float inf = std::numeric_limits<float>::infinity();
  for (int i = 0; i < 8; ++i) {
    for (int k = 0; k < 3; ++k) n.box[2 * k][i] = inf, n.box[2 * k + 1][i] = -inf;
    n.child[i] = 0;
  }
  return n;
}

void Bvh8Node::set(int i, std::uint32_t ref, const Box3f& b) {
  child[i] = ref;
  for (int k = 0; k < 3; ++k) box[2 * k][i] = b.lo[k], box[2 * k + 1][i] = b.hi[k];
}

Box3f Bvh8Node::child_box(int i) const {
  Box3f b;
  for (int k = 0; k < 3; ++k) b.lo[k] = box[2 * k][i], b.hi[k] = box[2 * k + 1][i];
  return b;
}

namespace {

bool contains(const Box3f& outer, const Box3f& inner) {
  for (int k = 0; k < 3; ++k)
    if (!(outer.lo[k] <= inner.lo[k] && inner.hi[k] <= outer.hi[k])) return false;
  return true;
}

struct Checker {
  const Bvh8Tree& t;
  std::vector<std::uint8_t> seen_node, seen_prim, seen_subtree;
  std::uint32_t leaves = 0;

  [[noreturn]] static void fail(const std::string& what) { throw std::logic_error("bvh8: " + what); }

  void check_ref(std::uint32_t ref, const Box3f& box, std::uint32_t depth) {
    const std::uint32_t i = Bvh8Node::index(ref);
    if (Bvh8Node::is_leaf(ref) && Bvh8Node::count(ref) == Bvh8Node::kSubtree) {
      if (!t.over_bsp) fail("subtree reference in a tree over triangles");
      if (i >= t.subtrees.size()) fail("subtree reference " + std::to_string(i) + " out of range");
      if (seen_subtree[i]++) fail("subtree " + std::to_string(i) + " referenced twice");
      if (!contains(box, t.subtrees[i].box)) fail("subtree " + std::to_string(i) + " outside its slot box");
      return;
    }
    if (Bvh8Node::is_leaf(ref)) {
      ++leaves;
      const std::uint32_t n = Bvh8Node::count(ref);
      if (n > Bvh8Node::kMaxLeafSize) fail("leaf at " + std::to_string(i) + " holds more than four triangles");
      if (std::uint64_t(i) + n > t.prims.size()) fail("leaf list " + std::to_string(i) + " out of range");
      const float* rows = t.leaf_soa.data() + Bvh8Tree::kSoaFloats * std::size_t(i);
      for (std::uint32_t j = i; j < i + n; ++j) {
        const std::uint32_t p = t.prims[j];
        if (p >= t.scene_triangles) fail("leaf entry " + std::to_string(j) + " names no triangle");
        if (seen_prim[p]++ && !t.over_bsp) fail("triangle " + std::to_string(p) + " in two leaves");
        if (Bvh8Tree::decode_prim(rows[9 * n + (j - i)]) != p)
          fail("leaf entry " + std::to_string(j) + ": SoA triangle number and list differ");
        for (int c = 0; c < 3; ++c) {
          const Vec3f& q = t.triangles[j].v[c];
          for (int k = 0; k < 3; ++k)
            if (!(rows[(3 * c + k) * n + (j - i)] == q[k]))
              fail("leaf entry " + std::to_string(j) + ": SoA rows and corners differ");
          Box3f b;
          b.extend(q);
          if (!t.over_bsp && !contains(box, b)) fail("triangle " + std::to_string(p) + " outside its leaf box");
        }
      }
      return;
    }
    if (i == 0 || i >= t.nodes.size()) fail("inner reference " + std::to_string(i) + " out of range");
    if (depth > t.depth) fail("deeper than the recorded depth " + std::to_string(t.depth));
    if (seen_node[i]++) fail("node " + std::to_string(i) + " reached twice");
    check_node(i, box, depth);
  }

  void check_node(std::uint32_t index, const Box3f& box, std::uint32_t depth) {
    const Bvh8Node& n = t.nodes[index];
    for (int s = 0; s < 8; ++s) {
      if (n.child[s] == 0) {
        if (!n.child_box(s).empty()) fail("empty slot with a box in node " + std::to_string(index));
        continue;
      }
      const Box3f b = n.child_box(s);
      if (!contains(box, b)) fail("child box outside its parent in node " + std::to_string(index));
      check_ref(n.child[s], b, depth + 1);
    }
  }
};

}  // namespace

void Bvh8Tree::validate() const {
  if (nodes.empty()) throw std::logic_error("bvh8: no root node");
  if (prims.size() != triangles.size()) throw std::logic_error("bvh8: prims and triangles differ in size");
  if (leaf_soa.size() != kSoaFloats * prims.size() + 3)
    throw std::logic_error("bvh8: leaf_soa is not " + std::to_string(kSoaFloats) + " floats per entry + 3");
  Checker c{*this, std::vector<std::uint8_t>(nodes.size(), 0), std::vector<std::uint8_t>(scene_triangles, 0),
            std::vector<std::uint8_t>(subtrees.size(), 0)};
  c.seen_node[0] = 1;
  Box3f all;
  for (int s = 0; s < 8; ++s) all.extend(nodes[0].child_box(s));
  c.check_node(0, all, 1);
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (!c.seen_node[i]) throw std::logic_error("bvh8: node " + std::to_string(i) + " is not reached");
  if (over_bsp) {
    for (std::size_t i = 0; i < subtrees.size(); ++i)
      if (!c.seen_subtree[i]) throw std::logic_error("bvh8: subtree " + std::to_string(i) + " is not reached");
    if (c.leaves + subtrees.size() != pieces)
      throw std::logic_error("bvh8: " + std::to_string(c.leaves + subtrees.size()) + " leaves and subtrees, built from " +
                             std::to_string(pieces) + " pieces");
    return;
  }
  if (!subtrees.empty()) throw std::logic_error("bvh8: subtrees in a tree over triangles");
  std::uint32_t missing = 0;
  for (std::uint32_t p = 0; p < scene_triangles; ++p) missing += c.seen_prim[p] ? 0 : 1;
  if (missing != left_out)
    throw std::logic_error("bvh8: " + std::to_string(missing) + " triangles in no leaf, " +
                           std::to_string(left_out) + " left out by the build");
}

}  // namespace bsprt
