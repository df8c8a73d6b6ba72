/// \file box_top_build.cpp
/// build_box_top: Embree's SAH BVH builder (rtcBuildBVH) with our own node
/// layout (traverse/bsp/bsp_boxtop.h). Embree makes the tree; the callbacks only record it,
/// and the result is copied into BoxTopNodes in depth-first order.
#include <embree3/rtcore.h>

#include <new>
#include <stdexcept>
#include <string>

#include "traverse/embree/box_top_build.h"
#include "traverse/embree/build_device.h"

namespace bsprt {
namespace {

/// Embree's rtcBuildBVH stops splitting at maxDepth and makes a leaf of
/// several subtrees, which create_leaf refuses (maxLeafSize 1), so the top is
/// at most kMaxDepth deep and trace_top's stack of 3·64 + 4 entries suffices.
constexpr unsigned kMaxDepth = 64;

/// Embree-allocated build node: inner (children) or leaf (a subtree).
struct BuildNode {
  bool leaf = false;
  std::uint32_t subtree = 0;  ///< leaf: index into the subtree list
  unsigned count = 0;
  BuildNode* child[4] = {};
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned int children, void*) {
  auto* n = new (rtcThreadLocalAlloc(alloc, sizeof(BuildNode), 16)) BuildNode;
  n->count = children;
  return n;
}
void set_children(void* node, void** child, unsigned int count, void*) {
  auto* n = static_cast<BuildNode*>(node);
  for (unsigned i = 0; i < count; ++i) n->child[i] = static_cast<BuildNode*>(child[i]);
}
/// Boxes are recomputed exactly when the tree is copied (Flattener::add).
void set_bounds(void*, const RTCBounds**, unsigned int, void*) {}
void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
  if (count != 1) return nullptr;  // maxLeafSize is 1
  auto* n = new (rtcThreadLocalAlloc(alloc, sizeof(BuildNode), 16)) BuildNode;
  n->leaf = true;
  n->subtree = prims[0].primID;
  return n;
}

/// A node with no children (every box empty, never entered).
BoxTopNode empty_node() {
  BoxTopNode n;
  for (int i = 0; i < 4; ++i) {
    n.child[i] = BoxTopNode::kNone;
    for (int k = 0; k < 3; ++k) n.lo[k][i] = 1.0f, n.hi[k][i] = 0.0f;
  }
  return n;
}

void set_child_box(BoxTopNode& n, int i, const Box3f& b) {
  for (int k = 0; k < 3; ++k) n.lo[k][i] = b.lo[k], n.hi[k][i] = b.hi[k];
}

struct Flattener {
  std::span<const BspSubtreeBox> subtrees;
  BoxTop top;

  /// Child reference of b, its box in `box`; inner nodes are appended depth
  /// first. The boxes are recomputed from the subtree boxes (exact min/max),
  /// not taken from the builder, so the certificate does not rest on Embree.
  std::uint32_t add(const BuildNode* b, Box3f& box, unsigned depth = 1) {
    if (b == nullptr) throw std::runtime_error("embree: rtcBuildBVH returned an incomplete tree");
    if (b->leaf) {
      box = subtrees[b->subtree].box;
      return BoxTopNode::kSubtree | subtrees[b->subtree].slot;
    }
    if (depth > kMaxDepth) throw std::runtime_error("embree: rtcBuildBVH exceeded the depth limit");
    if (b->count > 4) throw std::runtime_error("embree: rtcBuildBVH made a node of more than 4 children");
    const auto index = std::uint32_t(top.nodes.size());
    top.nodes.emplace_back();
    BoxTopNode n = empty_node();
    box = Box3f{};
    for (unsigned i = 0; i < b->count; ++i) {
      Box3f c;
      n.child[i] = add(b->child[i], c, depth + 1);
      set_child_box(n, int(i), c);
      box.extend(c);
    }
    top.nodes[index] = n;
    return index;
  }
};

}  // namespace

BoxTop build_box_top(std::span<const BspSubtreeBox> subtrees) {
  BoxTop top;
  if (subtrees.empty()) return top;
  top.subtrees = std::uint32_t(subtrees.size());
  if (subtrees.size() == 1) {  // Embree returns a bare leaf: give it a root node
    BoxTopNode n = empty_node();
    set_child_box(n, 0, subtrees[0].box);
    n.child[0] = BoxTopNode::kSubtree | subtrees[0].slot;
    top.nodes.push_back(n);
    return top;
  }
  std::vector<RTCBuildPrimitive> prims(subtrees.size());
  for (std::size_t i = 0; i < subtrees.size(); ++i) {
    const Box3f& b = subtrees[i].box;
    prims[i] = {b.lo.x, b.lo.y, b.lo.z, 0u, b.hi.x, b.hi.y, b.hi.z, std::uint32_t(i)};
  }
  // Rare (one build per tracer); Embree parallelizes each build itself.
  detail::EmbreeBuildSettings settings;
  settings.branching = 4;
  settings.max_depth = kMaxDepth;
  settings.max_leaf_size = 1;
  settings.create_node = create_node;
  settings.set_children = set_children;
  settings.set_bounds = set_bounds;
  settings.create_leaf = create_leaf;
  const detail::EmbreeBuild build(prims, prims.size(), settings);
  Flattener f{subtrees, {}};
  Box3f all;
  const std::uint32_t ref = f.add(static_cast<const BuildNode*>(build.root()), all);
  if (ref & BoxTopNode::kSubtree) {  // a bare leaf at the root (not expected with >= 2 subtrees)
    BoxTopNode n = empty_node();
    set_child_box(n, 0, all);
    n.child[0] = ref;
    f.top.nodes.push_back(n);
  }
  f.top.subtrees = top.subtrees;
  return std::move(f.top);
}

void add_box_top(BspTracer& tracer, std::uint32_t max_slots) {
  tracer.set_box_top(build_box_top(tracer.subtree_boxes(max_slots)));
}

}  // namespace bsprt
