/// \file bsp_build.cpp
/// Top-down exact BSP build (bsp_build.h): candidate evaluation, exact split,
/// parallel recursion, flattening into a BspTree, the build report.
#include "builder/bsp/bsp_build.h"

#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <unordered_map>

#include "builder/bsp/bsp_candidates.h"
#include "bsprt/error.h"
#include "geometry/core/check.h"
#include "geometry/core/fp_env.h"

namespace bsprt {

namespace {

/// The builder's own pointer tree; flattened into a BspTree at the end.
struct BuildNode {
  bool leaf = true;
  bool depth_limited = false;
  PlaneDef plane;
  double area = 0;    ///< cell area (SAH bookkeeping)
  double c_trav = 0;  ///< traversal cost of the chosen split
  std::vector<std::uint32_t> tris;
  std::unique_ptr<BuildNode> left, right;
};

/// One node's exact split: children cells and clipped triangle lists.
struct SplitResult {
  Cell left_cell, right_cell;
  std::vector<ClippedTriangle> left, right;
};

class Builder {
 public:
  Builder(const TriangleSoup& soup, const BspConfig& cfg, const BspProgressFn& progress, double total,
          double root_area)
      : soup_(soup), cfg_(cfg), progress_(progress), total_(total), root_area_(root_area) {}

  std::unique_ptr<BuildNode> build(Cell cell, std::vector<ClippedTriangle> tris, int depth,
                                   double weight);
  ExactStats stats() const { return stats_; }
  std::size_t failed_attempts() const { return failed_; }

 private:
  std::unique_ptr<BuildNode> make_leaf(const std::vector<ClippedTriangle>& tris, double weight,
                                       double area, bool depth_limited, const ExactStats& st);
  bool try_split(const Cell& cell, const std::vector<ClippedTriangle>& tris, const Candidate& c,
                 double area, SplitResult& out, ExactStats& st);
  void flush(const ExactStats& st, double done_weight);

 public:
  /// The last progress report is exactly (total, total): the leaves' weights are
  /// fractions summed in whatever order the threads finish, so their float sum can
  /// fall just short of the total (regression test "bsp: progress reaches the total").
  void finish() {
    std::lock_guard<std::mutex> lock(mu_);
    if (progress_ && reported_ < total_) progress_(total_, total_);
    reported_ = total_;
  }

 private:
  /// The split beats the leaf; and when one child keeps every triangle (the
  /// zoom around a shared vertex that the local SAH never stops), by at least
  /// BspConfig::min_gain (area weighted).
  bool worth_it(double cost, std::size_t n, double area, bool keeps_all) const {
    const double leaf = cfg_.c_isect * double(n);
    if (!(cost < leaf)) return false;
    if (!keeps_all && n > cfg_.min_gain_triangles) return true;
    return (leaf - cost) / cfg_.c_isect * (area / root_area_) >= cfg_.min_gain;
  }

  const TriangleSoup& soup_;
  const BspConfig& cfg_;
  const BspProgressFn& progress_;
  double total_;
  double root_area_;
  std::mutex mu_;
  ExactStats stats_;
  std::size_t failed_ = 0;
  double done_ = 0, reported_ = 0;
};

void Builder::flush(const ExactStats& st, double done_weight) {
  std::lock_guard<std::mutex> lock(mu_);
  stats_.add(st);
  done_ += done_weight;
  if (progress_ && (done_ - reported_ >= 1e-3 * total_ || done_ >= total_)) {
    reported_ = done_;
    progress_(std::min(done_, total_), total_);
  }
}

std::unique_ptr<BuildNode> Builder::make_leaf(const std::vector<ClippedTriangle>& tris,
                                              double weight, double area, bool depth_limited,
                                              const ExactStats& st) {
  auto n = std::make_unique<BuildNode>();
  n->area = area;
  n->depth_limited = depth_limited;
  for (const ClippedTriangle& c : tris) n->tris.push_back(c.tri);
  std::sort(n->tris.begin(), n->tris.end());
  flush(st, weight);
  return n;
}

bool Builder::try_split(const Cell& cell, const std::vector<ClippedTriangle>& tris,
                        const Candidate& c, double area, SplitResult& out, ExactStats& st) {
  RoundingGuard g;
  const PreparedPlane pp = prepare_plane(g, soup_, c.plane);
  if (!cell.split(g, soup_, pp, out.left_cell, out.right_cell, st)) return false;
  // Pass 1: exact signs of every clipped triangle, and the exact counts.
  const std::size_t n = tris.size();
  std::vector<std::vector<int>> signs(n);
  std::vector<SideSummary> sum(n);
  SplitCount count;
  for (std::size_t i = 0; i < n; ++i) {
    sum[i] = polygon_signs(g, soup_, pp, tris[i], signs[i], st);
    count.add(reach(sum[i], cfg_.membership));
  }
  bool coplanar_left = true;
  const double cost = sah_cost(cfg_, c.c_trav, count, c.area_left, c.area_right, area, &coplanar_left);
  if (!worth_it(cost, n, area, keeps_all(count, n))) return false;
  // Pass 2: clip into the children (a side is only clipped when the other side
  // has vertices strictly beyond the plane).
  for (std::size_t i = 0; i < n; ++i) {
    const Reach r = reach(sum[i], cfg_.membership);
    const bool to_left = r == Reach::Left || r == Reach::Both ||
                         (r == Reach::Coplanar && (cfg_.coplanar_to_both || coplanar_left));
    const bool to_right = r == Reach::Right || r == Reach::Both ||
                          (r == Reach::Coplanar && (cfg_.coplanar_to_both || !coplanar_left));
    if (to_left)
      out.left.push_back(sum[i].pos ? clip_polygon(g, soup_, pp, tris[i], signs[i], -1, st) : tris[i]);
    if (to_right)
      out.right.push_back(sum[i].neg ? clip_polygon(g, soup_, pp, tris[i], signs[i], +1, st) : tris[i]);
  }
  return true;
}

std::unique_ptr<BuildNode> Builder::build(Cell cell, std::vector<ClippedTriangle> tris, int depth,
                                          double weight) {
  ExactStats st;
  const std::size_t n = tris.size();
  std::vector<Candidate> cands;
  double area = 0;
  std::size_t nkd = 0;
  const bool bsp_planes = cfg_.face_candidates || cfg_.edge_candidates;
  const auto add_bsp = [&] {
    RoundingGuard g;
    add_bsp_candidates(g, soup_, make_node_view(soup_, cell, tris), cfg_, nkd > 0, cands, st);
  };
  {
    RoundingGuard g;
    const NodeView v = make_node_view(soup_, cell, tris);
    area = v.area;
    if (n == 0 || depth >= cfg_.max_depth) return make_leaf(tris, weight, area, n > 0, st);
    nkd = add_kd_candidates(v, cfg_, cands);
    if (n <= cfg_.bsp_max_triangles && bsp_planes) add_bsp_candidates(g, soup_, v, cfg_, nkd > 0, cands, st);
  }
  SplitResult sr;
  const Candidate* chosen = nullptr;
  // The cheapest candidates that pass worth_it are tried exactly; one that keeps
  // every triangle in a child and gains too little (often the empty-space cuts
  // around a small dense cluster) is passed over without using up an attempt.
  const auto choose = [&] {
    std::sort(cands.begin(), cands.end(), [](const Candidate& a, const Candidate& b) {
      return a.cost < b.cost || (a.cost == b.cost && a.plane < b.plane);
    });
    int attempts = 0;
    for (std::size_t k = 0; attempts < cfg_.max_split_attempts && k < cands.size(); ++k) {
      if (!(cands[k].cost < cfg_.c_isect * double(n))) break;  // sorted: no later one beats the leaf
      if (!worth_it(cands[k].cost, n, area, cands[k].keeps_all)) continue;
      ++attempts;
      sr = SplitResult{};
      if (try_split(cell, tris, cands[k], area, sr, st)) {
        chosen = &cands[k];
        return;
      }
      std::lock_guard<std::mutex> lock(mu_);
      ++failed_;
    }
  };
  choose();
  // Above bsp_max_triangles only kd planes are offered, since they almost always
  // win there. When none pays, the node would become a large leaf: a bundle of
  // long, thin, slanted triangles that every axis plane cuts (conference: a
  // 117-triangle leaf of slivers). Only then are face and edge planes evaluated
  // for it, as the paper's combined SAH would.
  if (!chosen && cfg_.bsp_max_triangles > 0 && n > cfg_.bsp_max_triangles && bsp_planes) {
    cands.clear();
    add_bsp();
    choose();
  }
  if (!chosen) return make_leaf(tris, weight, area, false, st);
  auto node = std::make_unique<BuildNode>();
  node->leaf = false;
  node->plane = chosen->plane;
  node->area = area;
  node->c_trav = chosen->c_trav;
  cell = Cell();
  tris.clear();
  tris.shrink_to_fit();
  const double nl = double(sr.left.size()), nr = double(sr.right.size());
  const double wl = nl + nr > 0 ? weight * nl / (nl + nr) : 0.5 * weight;
  flush(st, 0.0);
  if (n >= cfg_.parallel_min_triangles) {
    tbb::task_group tg;
    tg.run([&] { node->left = build(std::move(sr.left_cell), std::move(sr.left), depth + 1, wl); });
    node->right = build(std::move(sr.right_cell), std::move(sr.right), depth + 1, weight - wl);
    tg.wait();
  } else {
    node->left = build(std::move(sr.left_cell), std::move(sr.left), depth + 1, wl);
    node->right = build(std::move(sr.right_cell), std::move(sr.right), depth + 1, weight - wl);
  }
  return node;
}

/// Preorder flattening of the pointer tree, with the report's statistics.
struct Flattener {
  std::vector<PlaneDef> planes;
  std::unordered_map<std::uint64_t, std::uint32_t> plane_index;
  std::vector<BspNode> nodes;
  std::vector<std::uint32_t> refs;
  BspBuildReport rep;
  double root_area = 1;

  void bump(std::vector<std::size_t>& v, std::size_t i) {
    if (v.size() <= i) v.resize(i + 1, 0);
    ++v[i];
  }

  std::uint32_t add(const BuildNode& b, std::size_t depth) {
    const std::uint32_t id = static_cast<std::uint32_t>(nodes.size());
    nodes.push_back({});
    const double p = root_area > 0 ? b.area / root_area : 0;
    if (b.leaf) {
      nodes[id] = {BspNode::kLeaf, static_cast<std::uint32_t>(refs.size()),
                   static_cast<std::uint32_t>(b.tris.size())};
      refs.insert(refs.end(), b.tris.begin(), b.tris.end());
      ++rep.leaves;
      rep.empty_leaves += b.tris.empty();
      rep.depth_limited += b.depth_limited;
      rep.max_depth = std::max(rep.max_depth, depth);
      bump(rep.leaf_histogram, b.tris.size());
      return id;
    }
    auto [it, fresh] = plane_index.try_emplace(b.plane.key(), static_cast<std::uint32_t>(planes.size()));
    if (fresh) planes.push_back(b.plane);
    bump(b.plane.is_kd() ? rep.kd_by_depth : rep.bsp_by_depth, depth);
    (b.plane.is_kd() ? rep.kd_splits : rep.bsp_splits) += 1;
    rep.sah_cost += p * b.c_trav;
    const std::uint32_t l = add(*b.left, depth + 1);
    const std::uint32_t r = add(*b.right, depth + 1);
    nodes[id] = {it->second, l, r};
    return id;
  }
};

double leaf_sah(const BuildNode& b, double root_area, double c_isect) {
  if (b.leaf) return root_area > 0 ? b.area / root_area * c_isect * double(b.tris.size()) : 0;
  return leaf_sah(*b.left, root_area, c_isect) + leaf_sah(*b.right, root_area, c_isect);
}

}  // namespace

Box3f bsp_root_box(const TriangleSoup& soup, const std::vector<std::uint32_t>& triangles) {
  Box3f b;
  for (std::uint32_t t : triangles)
    for (int k = 0; k < 3; ++k) b.extend(soup.corner(t, k));
  if (b.empty()) return Box3f{{0, 0, 0}, {1, 1, 1}};
  const Vec3f d = b.diagonal();
  const float e = std::max({d.x, d.y, d.z});
  for (int a = 0; a < 3; ++a) {
    if (b.lo[a] < b.hi[a]) continue;
    const float pad = std::max(e * 1e-3f, std::numeric_limits<float>::min());
    b.lo[a] = std::nextafter(b.lo[a] - pad, -std::numeric_limits<float>::infinity());
    b.hi[a] = std::nextafter(b.hi[a] + pad, std::numeric_limits<float>::infinity());
  }
  return b;
}

BspTree build_bsp(const TriangleSoup& soup, const BspConfig& config, BspBuildReport* report,
                  const BspProgressFn& progress) {
  check_threads(config.threads, "BspConfig::threads");
  const IeeeScope ieee;  // IEEE arithmetic here and, through the arena made below, in every task (fp_env.h)
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::uint32_t> ids;
  for (std::uint32_t t = 0; t < soup.size(); ++t)
    if (!soup.is_degenerate(t) && !triangle_degenerate_exact(soup, t)) ids.push_back(t);
  const Box3f root_box = bsp_root_box(soup, ids);
  std::vector<ClippedTriangle> tris;
  tris.reserve(ids.size());
  for (std::uint32_t t : ids) tris.push_back(full_triangle(soup, t));
  const Vec3f d = root_box.diagonal();
  const double root_area = 2.0 * (double(d.x) * d.y + double(d.y) * d.z + double(d.z) * d.x);
  Builder builder(soup, config, progress, double(ids.size()), root_area);
  std::unique_ptr<BuildNode> root;
  tbb::task_arena arena(config.threads > 0 ? config.threads : tbb::task_arena::automatic);  // under `ieee`
  arena.execute([&] { root = builder.build(Cell::box(root_box), std::move(tris), 0, double(ids.size())); });
  builder.finish();
  Flattener f;
  f.root_area = root->area;
  f.add(*root, 0);
  f.rep.sah_cost += leaf_sah(*root, root->area, config.c_isect);
  BspTree tree(root_box, std::move(f.planes), std::move(f.nodes), std::move(f.refs),
               config.membership, config.coplanar_to_both);
  if (report) {
    BspBuildReport& r = *report;
    r = std::move(f.rep);
    r.triangles = soup.size();
    r.degenerate = soup.size() - ids.size();
    r.nodes = tree.nodes().size();
    r.triangle_refs = tree.triangle_refs().size();
    r.failed_split_attempts = builder.failed_attempts();
    r.exact = builder.stats();
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return tree;
}

}  // namespace bsprt
