/// \file bvh8_build.cpp
/// build_bvh8: rtcBuildBVH with maxBranchingFactor 8 records Embree's SAH
/// tree; Flattener copies it depth first into Bvh8Nodes with exact boxes.
#include "traverse/embree/bvh8_build.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <span>
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
  const TriangleSoup* soup = nullptr;        ///< a tree over triangles
  const BspTracer* bsp = nullptr;            ///< a tree over pieces of a BSP
  std::span<const BspSubtreeBox> pieces;     ///< those pieces (build primitive i = pieces[i])
  Bvh8Tree tree;

  [[noreturn]] static void fail(const std::string& what) { throw std::runtime_error("embree: rtcBuildBVH " + what); }

  /// Appends one leaf of n (1..4) triangles, numbers and corners; returns its reference.
  std::uint32_t put_leaf(const std::uint32_t* prims, const LeafTriangle* tris, std::uint32_t n) {
    const auto first = std::uint32_t(tree.prims.size());
    const std::size_t rows = tree.leaf_soa.size();
    tree.leaf_soa.resize(rows + Bvh8Tree::kSoaFloats * std::size_t(n));
    for (std::uint32_t i = 0; i < n; ++i) {
      tree.prims.push_back(prims[i]);
      tree.triangles.push_back(tris[i]);
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) tree.leaf_soa[rows + (3 * j + k) * n + i] = tris[i].v[j][k];
      tree.leaf_soa[rows + 9 * n + i] = Bvh8Tree::encode_prim(prims[i]);
    }
    return Bvh8Node::leaf_ref(first, n);
  }

  /// Build primitive(s) ids[0..n) as one leaf: n (<= 4) triangles of the
  /// soup, whose box is that of their corners; or one BSP piece, whose box is
  /// its certified box: a triangle leaf when it is a leaf cell of at most four
  /// triangles, else a subtree reference.
  std::uint32_t leaf(const std::uint32_t* ids, std::uint32_t n, Box3f& box) {
    if (bsp != nullptr) {
      const BspSubtreeBox& p = pieces[ids[0]];
      box = p.box;
      if (p.triangles >= 1 && p.triangles <= Bvh8Node::kMaxLeafSize) {
        std::uint32_t prims[Bvh8Node::kMaxLeafSize];
        LeafTriangle tris[Bvh8Node::kMaxLeafSize];
        std::uint32_t n = 0;
        for (const std::uint32_t e : bsp_subtree_entries(bsp->compact(), bsp->leaf_prims(), p.slot)) {
          if (n == Bvh8Node::kMaxLeafSize) fail("piece lists more triangles than it recorded");
          prims[n] = bsp->leaf_prims()[e];
          tris[n++] = bsp->leaf_triangles()[e];
        }
        if (n != p.triangles) fail("piece lists other triangles than it recorded");
        return put_leaf(prims, tris, n);
      }
      tree.subtrees.push_back({p.slot, p.box});
      return Bvh8Node::subtree_ref(std::uint32_t(tree.subtrees.size() - 1));
    }
    LeafTriangle tris[Bvh8Node::kMaxLeafSize];
    box = Box3f{};
    for (std::uint32_t i = 0; i < n; ++i) {
      const auto c = soup->corners(ids[i]);
      tris[i] = {{c[0], c[1], c[2]}};
      for (const Vec3f& q : c) box.extend(q);
    }
    return put_leaf(ids, tris, n);
  }

  /// A list too long for one leaf (more than four triangles, more than one
  /// piece): an inner node over up to 8 shorter lists.
  std::uint32_t long_leaf(const std::uint32_t* ids, std::uint32_t n, Box3f& box, std::uint32_t depth) {
    if (n <= (bsp != nullptr ? 1u : Bvh8Node::kMaxLeafSize)) return leaf(ids, n, box);
    const auto index = std::uint32_t(tree.nodes.size());
    tree.nodes.push_back(Bvh8Node::empty());
    tree.depth = std::max(tree.depth, depth);
    Bvh8Node node = Bvh8Node::empty();
    box = Box3f{};
    const std::uint32_t part = (n + 7) / 8;
    for (std::uint32_t s = 0, at = 0; at < n; ++s, at += part) {
      Box3f b;
      node.set(int(s), long_leaf(ids + at, std::min(part, n - at), b, depth + 1), b);
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

  /// Runs Embree's builder over prims[0..count) (capacity 2 count) and copies its tree under the root.
  void build(std::vector<RTCBuildPrimitive>& prims, std::size_t count, unsigned max_leaf_size,
             float traversal_cost, float intersection_cost, unsigned min_leaf_size = 1,
             unsigned sah_block_size = 1) {
    tree.nodes.push_back(Bvh8Node::empty());  // the root, filled below
    tree.depth = 1;
    if (count > 0) {
      prims.resize(count * 2);  // Embree's builder may use spare capacity
      detail::EmbreeBuildSettings settings;
      settings.branching = 8;
      settings.max_depth = kMaxDepth;
      settings.max_leaf_size = max_leaf_size;
      settings.traversal_cost = traversal_cost;
      settings.intersection_cost = intersection_cost;
      settings.min_leaf_size = min_leaf_size;
      settings.sah_block_size = sah_block_size;
      settings.create_node = create_node;
      settings.set_children = set_children;
      settings.set_bounds = set_bounds;
      settings.create_leaf = create_leaf;
      const detail::EmbreeBuild run(prims, count, settings);
      const auto* root = static_cast<const BuildNode*>(run.root());
      Bvh8Node top = Bvh8Node::empty();
      if (root->leaf) {  // a small scene: one leaf (or a few) under the root
        Box3f b;
        top.set(0, long_leaf(root->prims, root->count, b, 2), b);
      } else {
        if (root->count > 8) fail("made a node of more than 8 children");
        for (unsigned i = 0; i < root->count; ++i) {
          Box3f b;
          top.set(int(i), add(root->child[i], b, 2), b);
        }
      }
      tree.nodes[0] = top;
    }
    tree.leaf_soa.insert(tree.leaf_soa.end(), 3, 0.0f);  // a row's four-float load may read past the last
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
  if (config.min_leaf_size < 1 || config.min_leaf_size > config.max_leaf_size)
    throw UsageError("bvh8: min_leaf_size must be 1..max_leaf_size (" + std::to_string(config.max_leaf_size) +
                     "), got " + std::to_string(config.min_leaf_size));
  if (config.sah_block_size < 1)
    throw UsageError("bvh8: sah_block_size must be at least 1");
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
  Flattener f;
  f.soup = &soup;
  f.tree.scene_triangles = std::uint32_t(soup.size());
  f.tree.left_out = left_out;
  f.build(prims, prims.size(), config.max_leaf_size, config.traversal_cost, config.intersection_cost,
          config.min_leaf_size, config.sah_block_size);
  return std::move(f.tree);
}

Bvh8Tree build_bvh8_over_bsp(const BspTracer& bsp, std::uint32_t max_slots, std::uint32_t leaf_triangles) {
  if (max_slots < 1) throw UsageError("bvh8 top: max_slots must be at least 1");
  if (leaf_triangles > Bvh8Node::kMaxLeafSize)
    throw UsageError("bvh8 top: leaf_triangles must be 0.." + std::to_string(Bvh8Node::kMaxLeafSize));
  const std::vector<BspSubtreeBox> pieces = bsp.subtree_boxes(max_slots, leaf_triangles);
  std::vector<RTCBuildPrimitive> prims;
  prims.reserve(2 * pieces.size());
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const Box3f& b = pieces[i].box;
    prims.push_back({b.lo.x, b.lo.y, b.lo.z, 0u, b.hi.x, b.hi.y, b.hi.z, std::uint32_t(i)});
  }
  Flattener f;
  f.bsp = &bsp;
  f.pieces = pieces;
  f.tree.over_bsp = true;
  f.tree.pieces = std::uint32_t(pieces.size());
  f.tree.scene_triangles = bsp.scene_triangles();
  // One piece per leaf; Embree's default costs for its BVH8 (a piece is
  // priced like a triangle: most are leaf cells of one to four).
  f.build(prims, prims.size(), 1, 1.0f, 0.1f);
  return std::move(f.tree);
}

void add_bvh8_top(BspTracer& tracer, std::uint32_t max_slots) {
  tracer.set_bvh8_top(build_bvh8_over_bsp(tracer, max_slots));
}

}  // namespace bsprt
