#include "builder/kd/kd_build.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>

#include <oneapi/tbb/enumerable_thread_specific.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/parallel_sort.h>
#include <oneapi/tbb/task_group.h>

#include "builder/kd/kd_events.h"
#include "bsprt/error.h"
#include "geometry/core/fp_env.h"
#include "traverse/kd/kd_traverse.h"

namespace bsprt {
namespace {

using kd_detail::NodeEvents;
using kd_detail::SplitChoice;
using kd_detail::SplitScratch;

/// The builder's own tree; flattened once into KdTree (pbrt's flattenBVH).
struct BuildNode {
  int axis = -1;  ///< -1 = leaf
  float split = 0.0f;
  std::unique_ptr<BuildNode> child[2];
  std::vector<std::uint32_t> prims;
};

/// State shared by all build tasks.
struct BuildContext {
  const KdConfig& config;
  std::vector<std::array<Vec3f, 3>> triangles;  ///< corners, by triangle number
  int depth_limit = 0;
  tbb::enumerable_thread_specific<SplitScratch> scratch;
  std::atomic<std::size_t> clipped{0}, dropped{0};

  explicit BuildContext(const KdConfig& c) : config(c) {}

  SplitScratch& local_scratch() {
    SplitScratch& s = scratch.local();
    if (s.side.size() != triangles.size()) {
      s.side.assign(triangles.size(), 0);
      s.bounds.assign(triangles.size(), Box3f{});
    }
    return s;
  }
};

void make_leaf(NodeEvents& node, BuildNode& out) {
  out.axis = -1;
  out.prims = std::move(node.tris);
  std::sort(out.prims.begin(), out.prims.end());
  for (auto& e : node.ev) std::vector<kd_detail::Event>().swap(e);
}

/// W&H's recursive build; subtrees above the threshold run as oneTBB tasks.
/// No task waits between classification and the end of split_events, so the
/// per-thread scratch is never shared by two nodes at once.
void build_node(NodeEvents&& node, const Box3f& cell, int depth, BuildContext& ctx, BuildNode& out) {
  const KdConfig& c = ctx.config;
  if (depth >= ctx.depth_limit || node.size() <= std::size_t(std::max(c.leaf_size, 0)))
    return make_leaf(node, out);
  const SplitChoice split = kd_detail::find_best_split(node, cell, c);
  if (split.axis < 0) return make_leaf(node, out);
  NodeEvents lower, upper;
  const kd_detail::SplitCounts counts = kd_detail::split_events(
      node, cell, split, ctx.triangles, c.perfect_splits, ctx.local_scratch(), lower, upper);
  ctx.clipped += counts.clipped;
  ctx.dropped += counts.dropped;
  out.axis = split.axis;
  out.split = split.pos;
  out.child[0] = std::make_unique<BuildNode>();
  out.child[1] = std::make_unique<BuildNode>();
  Box3f lo_cell = cell, hi_cell = cell;
  lo_cell.hi[split.axis] = split.pos;
  hi_cell.lo[split.axis] = split.pos;
  const std::size_t threshold = std::size_t(std::max(c.parallel_threshold, 1));
  if (lower.size() >= threshold && upper.size() >= threshold) {
    tbb::task_group group;
    group.run([&] { build_node(std::move(lower), lo_cell, depth + 1, ctx, *out.child[0]); });
    build_node(std::move(upper), hi_cell, depth + 1, ctx, *out.child[1]);
    group.wait();
  } else {
    build_node(std::move(lower), lo_cell, depth + 1, ctx, *out.child[0]);
    build_node(std::move(upper), hi_cell, depth + 1, ctx, *out.child[1]);
  }
}

/// Depth-first flattening, lower child adjacent to its parent.
void flatten(const BuildNode& n, KdTree& tree) {
  if (n.axis < 0) {
    if (tree.prims.size() + n.prims.size() > KdNode::kMaxOffset)
      throw UsageError("kd-tree: more than 2^30 leaf references");
    tree.nodes.push_back(KdNode::make_leaf(std::uint32_t(tree.prims.size()), std::uint32_t(n.prims.size())));
    tree.prims.insert(tree.prims.end(), n.prims.begin(), n.prims.end());
    return;
  }
  const std::size_t self = tree.nodes.size();
  tree.nodes.push_back(KdNode{});
  flatten(*n.child[0], tree);
  if (tree.nodes.size() > KdNode::kMaxOffset) throw UsageError("kd-tree: more than 2^30 nodes");
  tree.nodes[self] = KdNode::make_inner(n.axis, n.split, std::uint32_t(tree.nodes.size()));
  flatten(*n.child[1], tree);
}

/// Root events: unclipped triangle bounds, each axis sorted once (W&H Sec. 4.4).
NodeEvents root_events(const TriangleSoup& soup, BuildContext& ctx, Box3f& bounds) {
  NodeEvents root;
  for (std::uint32_t t = 0; t < soup.size(); ++t) {
    ctx.triangles[t] = soup.corners(t);
    if (soup.is_degenerate(t)) continue;
    Box3f b;
    for (const Vec3f& p : ctx.triangles[t]) b.extend(p);
    if (!is_finite(b.lo) || !is_finite(b.hi)) continue;  // never hit
    bounds.extend(b);
    root.add(t, b);
  }
  tbb::parallel_for(0, 3, [&](int k) { tbb::parallel_sort(root.ev[k].begin(), root.ev[k].end()); });
  return root;
}

/// Frees a build tree iteratively (deep trees would overflow recursive destructors).
void free_tree(std::unique_ptr<BuildNode> root) {
  std::vector<std::unique_ptr<BuildNode>> stack;
  stack.push_back(std::move(root));
  while (!stack.empty()) {
    std::unique_ptr<BuildNode> n = std::move(stack.back());
    stack.pop_back();
    for (auto& c : n->child)
      if (c) stack.push_back(std::move(c));
  }
}

}  // namespace

int kd_depth_limit(const KdConfig& config, std::size_t n) {
  const int limit = config.max_depth > 0
                        ? config.max_depth
                        : int(std::lround(8.0 + 1.3 * std::log2(double(std::max<std::size_t>(n, 1)))));
  return std::min(limit, kKdMaxDepth - 1);  // the traversal stack's size
}

namespace {
KdTree build_kd_ieee(const TriangleSoup& soup, const KdConfig& config, KdBuildReport* report) {
  const auto start = std::chrono::steady_clock::now();
  if (soup.size() > KdNode::kMaxOffset)
    throw UsageError("kd-tree: " + std::to_string(soup.size()) + " triangles, at most 2^30 - 1 supported");
  BuildContext ctx(config);
  ctx.triangles.resize(soup.size());
  KdTree tree;
  tree.triangle_count = std::uint32_t(soup.size());
  NodeEvents root = root_events(soup, ctx, tree.bounds);
  ctx.depth_limit = kd_depth_limit(config, root.size());
  auto build_root = std::make_unique<BuildNode>();
  build_node(std::move(root), tree.bounds, 0, ctx, *build_root);
  flatten(*build_root, tree);
  free_tree(std::move(build_root));
  if (report) {
    const KdTreeStats s = kd_tree_stats(tree);
    report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    report->nodes = s.nodes;
    report->leaves = s.leaves;
    report->empty_leaves = s.empty_leaves;
    report->avg_leaf_size = s.avg_leaf_size;
    report->max_depth = s.max_depth;
    report->depth_limit = ctx.depth_limit;
    report->bytes = s.bytes;
    report->clipped = ctx.clipped;
    report->dropped = ctx.dropped;
  }
  return tree;
}
}  // namespace

KdTree build_kd(const TriangleSoup& soup, const KdConfig& config, KdBuildReport* report) {
  // IEEE arithmetic in every task, whatever the caller's thread or arena holds (fp_env.h).
  return run_ieee(0, [&] { return build_kd_ieee(soup, config, report); });
}

}  // namespace bsprt
