/// \file kd_file.cpp
/// kd-tree <-> tree file.
#include "builder/kd/kd_file.h"

#include <stdexcept>

#include "builder/root_box.h"
#include "traverse/kd/kd_traverse.h"

namespace bsprt {
namespace {

/// KdConfig as stored (fixed layout, 32 bytes).
struct ConfigRecord {
  float traversal_cost;
  float intersection_cost;
  float empty_bonus;
  std::int32_t max_depth;
  std::int32_t leaf_size;
  std::int32_t parallel_threshold;
  std::uint32_t perfect_splits;
  std::uint32_t reserved;
};
static_assert(sizeof(ConfigRecord) == 32);

struct BoundsRecord {
  float lo[3];
  float hi[3];
};
static_assert(sizeof(BoundsRecord) == 24);

}  // namespace

void write_kd_tree(const std::string& path, const KdTree& tree, const TriangleSoup& soup,
                   const KdConfig& config) {
  kd_tree_file(tree, soup, config).write(path);
}

TreeFileWriter kd_tree_file(const KdTree& tree, const TriangleSoup& soup, const KdConfig& config) {
  TreeFileWriter w(TreeKind::Kd, soup);
  w.add_array(kKdNodesTag, tree.nodes);
  w.add_array(kKdPrimsTag, tree.prims);
  const BoundsRecord b{{tree.bounds.lo.x, tree.bounds.lo.y, tree.bounds.lo.z},
                       {tree.bounds.hi.x, tree.bounds.hi.y, tree.bounds.hi.z}};
  w.add_array(kKdBoundsTag, std::vector<BoundsRecord>{b});
  const ConfigRecord c{config.traversal_cost, config.intersection_cost, config.empty_bonus,
                       config.max_depth, config.leaf_size, config.parallel_threshold,
                       config.perfect_splits ? 1u : 0u, 0u};
  w.add_array(kKdConfigTag, std::vector<ConfigRecord>{c});
  return w;
}

KdTree read_kd_tree(const std::string& path, const TriangleSoup& soup, KdConfig* config) {
  return read_kd_tree(TreeFileReader(path), soup, config);
}

KdTree read_kd_tree(const TreeFileReader& r, const TriangleSoup& soup, KdConfig* config) {
  const std::string& path = r.path();
  if (r.kind() != TreeKind::Kd) throw InputError(path, "not a kd tree file (it holds another tree kind)");
  r.check_scene(soup);
  KdTree tree = read_kd_sections(r, std::uint32_t(soup.size()), config);
  check_root_box(path, "kd-tree root box", tree.bounds, soup);
  return tree;
}

KdTree read_kd_sections(const TreeFileReader& r, std::uint32_t triangle_count, KdConfig* config) {
  const std::string& path = r.path();
  KdTree tree;
  tree.triangle_count = triangle_count;
  tree.nodes = r.array<KdNode>(kKdNodesTag);
  tree.prims = r.array<std::uint32_t>(kKdPrimsTag);
  const BoundsRecord b = r.record<BoundsRecord>(kKdBoundsTag);
  tree.bounds.lo = {b.lo[0], b.lo[1], b.lo[2]};
  tree.bounds.hi = {b.hi[0], b.hi[1], b.hi[2]};
  check_box_finite(path, "kd-tree root box", tree.bounds);
  const ConfigRecord c = r.record<ConfigRecord>(kKdConfigTag);
  if (config) {
    *config = KdConfig{c.traversal_cost, c.intersection_cost, c.empty_bonus, c.max_depth,
                       c.leaf_size,      c.parallel_threshold, c.perfect_splits != 0};
  }
  try {
    tree.validate();
  } catch (const std::logic_error& e) {
    throw InputError(path, std::string("invalid kd-tree: ") + e.what());
  }
  if (kd_tree_stats(tree).max_depth >= kKdMaxDepth)
    throw InputError(path, "kd-tree deeper than " + std::to_string(kKdMaxDepth) + " levels");
  return tree;
}

}  // namespace bsprt
