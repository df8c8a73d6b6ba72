/// \file bvh8_build.cpp
/// build_bvh8: rtcBuildBVH with maxBranchingFactor 8 records Embree's SAH
/// tree; Flattener copies it depth first into Bvh8Nodes with exact boxes.
#include "traverse/embree/bvh8_build.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <new>
#include <stdexcept>
#include <string>

#include "bsprt/error.h"
#include "traverse/embree/build_device.h"

namespace bsprt {
namespace {

/// Embree's depth limit for the build; a leaf it makes there may hold more
/// than max_leaf_size triangles, which Flattener splits into 8-wide levels
/// of leaves of at most four.
constexpr unsigned kMaxDepth = 48;

/// Embree-allocated build node: inner (up to 8 children) or leaf (triangles).
struct BuildNode {
  bool leaf = false;
  unsigned count = 0;  ///< children, or triangles of a leaf
  BuildNode* child[8] = {};
  std::uint32_t* prims = nullptr;  ///< leaf: `count` triangle numbers
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned int children, void*) {
  auto* n = new (rtcThreadLocalAlloc(alloc, sizeof(BuildNode), 16)) BuildNode;
  n->count = children;
  return n;
}
void set_children(void* node, void** child, unsigned int count, void*) {
  auto* n = static_cast<BuildNode*>(node);
  for (unsigned i = 0; i < count && i < 8; ++i) n->child[i] = static_cast<BuildNode*>(child[i]);
}
/// Boxes are recomputed from the corners when the tree is copied.
void set_bounds(void*, const RTCBounds**, unsigned int, void*) {}
void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
  auto* n = new (rtcThreadLocalAlloc(alloc, sizeof(BuildNode), 16)) BuildNode;
  n->leaf = true;
  n->count = unsigned(count);
  n->prims = static_cast<std::uint32_t*>(rtcThreadLocalAlloc(alloc, sizeof(std::uint32_t) * count, 16));
  for (size_t i = 0; i < count; ++i) n->prims[i] = prims[i].primID;
  return n;
}

struct Flattener {
  const TriangleSoup& soup;
  Bvh8Tree tree;

  [[noreturn]] static void fail(const std::string& what) { throw std::runtime_error("embree: rtcBuildBVH " + what); }

  /// Appends the triangles prims[0..n) (n <= 4) as one leaf; returns its reference and box.
  std::uint32_t leaf(const std::uint32_t* prims, std::uint32_t n, Box3f& box) {
    const auto first = std::uint32_t(tree.prims.size());
    const std::size_t rows = tree.leaf_soa.size();
    tree.leaf_soa.resize(rows + 9 * std::size_t(n));
    box = Box3f{};
    for (std::uint32_t i = 0; i < n; ++i) {
      const auto c = soup.corners(prims[i]);
      tree.prims.push_back(prims[i]);
      tree.triangles.push_back({{c[0], c[1], c[2]}});
      for (int j = 0; j < 3; ++j) {
        box.extend(c[j]);
        for (int k = 0; k < 3; ++k) tree.leaf_soa[rows + (3 * j + k) * n + i] = c[j][k];
      }
    }
    return Bvh8Node::leaf_ref(first, n);
  }

  /// A list too long for one leaf: an inner node over up to 8 shorter lists.
  std::uint32_t long_leaf(const std::uint32_t* prims, std::uint32_t n, Box3f& box, std::uint32_t depth) {
    if (n <= Bvh8Node::kMaxLeafSize) return leaf(prims, n, box);
    const auto index = std::uint32_t(tree.nodes.size());
    tree.nodes.push_back(Bvh8Node::empty());
    tree.depth = std::max(tree.depth, depth);
    Bvh8Node node = Bvh8Node::empty();
    box = Box3f{};
    const std::uint32_t part = (n + 7) / 8;
    for (std::uint32_t s = 0, at = 0; at < n; ++s, at += part) {
      Box3f b;
      node.set(int(s), long_leaf(prims + at, std::min(part, n - at), b, depth + 1), b);
      box.extend(b);
    }
    tree.nodes[index] = node;
    return Bvh8Node::inner_ref(index);
  }

  /// Reference of b (inner nodes appended depth first) and its exact box.
  std::uint32_t add(const BuildNode* b, Box3f& box, std::uint32_t depth) {
    if (b == nullptr) fail("returned an incomplete tree");
    if (b->leaf) {
      if (b->count == 0) fail("made an empty leaf");
      return long_leaf(b->prims, b->count, box, depth);
    }
    if (b->count > 8) fail("made a node of more than 8 children");
    const auto index = std::uint32_t(tree.nodes.size());
    tree.nodes.push_back(Bvh8Node::empty());
    tree.depth = std::max(tree.depth, depth);
    Bvh8Node node = Bvh8Node::empty();
    box = Box3f{};
    for (unsigned i = 0; i < b->count; ++i) {
      Box3f c;
      node.set(int(i), add(b->child[i], c, depth + 1), c);
      box.extend(c);
    }
    tree.nodes[index] = node;
    return Bvh8Node::inner_ref(index);
  }
};

bool usable(const TriangleSoup& soup, std::uint32_t t) {
  if (soup.is_degenerate(t)) return false;
  for (const Vec3f& p : soup.corners(t))
    if (!is_finite(p)) return false;
  return true;
}

}  // namespace

Bvh8Tree build_bvh8(const TriangleSoup& soup, const Bvh8Config& config) {
  if (config.max_leaf_size < 1 || config.max_leaf_size > Bvh8Node::kMaxLeafSize)
    throw UsageError("bvh8: max_leaf_size must be 1.." + std::to_string(Bvh8Node::kMaxLeafSize) + ", got " +
                     std::to_string(config.max_leaf_size));
  std::vector<RTCBuildPrimitive> prims;
  prims.reserve(soup.size());
  std::uint32_t left_out = 0;
  for (std::uint32_t t = 0; t < soup.size(); ++t) {
    if (!usable(soup, t)) {
      ++left_out;
      continue;
    }
    Box3f b;
    for (const Vec3f& p : soup.corners(t)) b.extend(p);
    prims.push_back({b.lo.x, b.lo.y, b.lo.z, 0u, b.hi.x, b.hi.y, b.hi.z, t});
  }
  Flattener f{soup, {}};
  f.tree.scene_triangles = std::uint32_t(soup.size());
  f.tree.left_out = left_out;
  f.tree.nodes.push_back(Bvh8Node::empty());  // the root, filled below
  f.tree.depth = 1;
  if (prims.empty()) {
    f.tree.leaf_soa.assign(3, 0.0f);
    return std::move(f.tree);
  }

  const std::size_t count = prims.size();
  prims.resize(count * 2);  // Embree's builder may use spare capacity
  detail::EmbreeBuildSettings settings;
  settings.branching = 8;
  settings.max_depth = kMaxDepth;
  settings.max_leaf_size = config.max_leaf_size;
  settings.traversal_cost = config.traversal_cost;
  settings.intersection_cost = config.intersection_cost;
  settings.create_node = create_node;
  settings.set_children = set_children;
  settings.set_bounds = set_bounds;
  settings.create_leaf = create_leaf;
  const detail::EmbreeBuild build(prims, count, settings);
  const auto* root = static_cast<const BuildNode*>(build.root());
  Bvh8Node top = Bvh8Node::empty();
  if (root->leaf) {  // a small scene: one leaf (or a few) under the root
    Box3f b;
    top.set(0, f.long_leaf(root->prims, root->count, b, 2), b);
  } else {
    if (root->count > 8) Flattener::fail("made a node of more than 8 children");
    for (unsigned i = 0; i < root->count; ++i) {
      Box3f b;
      top.set(int(i), f.add(root->child[i], b, 2), b);
    }
  }
  f.tree.nodes[0] = top;
  f.tree.leaf_soa.insert(f.tree.leaf_soa.end(), 3, 0.0f);  // a row's four-float load may read past the last
  return std::move(f.tree);
}

}  // namespace bsprt
