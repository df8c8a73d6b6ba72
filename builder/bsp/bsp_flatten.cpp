/// \file bsp_flatten.cpp
/// The exact → float bridge (bsp_flatten.h). The only file that knows both the
/// exact tree (builder/bsp_tree.h, robust/) and the flat tree (traverse/).
#include "builder/bsp/bsp_flatten.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "bsprt/error.h"
#include "geometry/core/fp_env.h"
#include "robust/exact_side.h"

namespace bsprt {
namespace {

/// How one exact inner node becomes a flat node.
struct NodePlan {
  FlatBspNodeKind kind = FlatBspNodeKind::Leaf;
  FloatPlane plane;      ///< plane nodes
  float split = 0.0f;    ///< kd nodes
  bool swap = false;     ///< first flat child is the exact right child
};

/// Axis k when the exact normal is exactly a multiple of e_k (two components
/// are exactly 0), with the sign of that multiple; -1 otherwise.
int exact_axis(const PreparedPlane& p, int& sign) {
  int zeros = 0, axis = -1;
  for (int i = 0; i < 3; ++i) {
    if (p.n_lo[i] == 0.0 && p.n_hi[i] == 0.0) ++zeros;
    else axis = i;
  }
  if (zeros != 2) return -1;
  sign = p.n_lo[axis] > 0.0 ? 1 : (p.n_hi[axis] < 0.0 ? -1 : 0);
  return sign == 0 ? -1 : axis;
}

/// Vertex enclosures of a cell.
std::vector<IntervalBox> vertex_boxes(const Cell& cell) {
  std::vector<IntervalBox> boxes;
  boxes.reserve(cell.vertices().size());
  for (const CellVertex& v : cell.vertices()) boxes.push_back(v.point.box);
  return boxes;
}

/// The plan of an inner node whose plane is `def` and cell `cell`.
NodePlan plan_node(const TriangleSoup& soup, PlaneDef def, const Cell& cell) {
  NodePlan plan;
  if (def.is_kd()) {
    plan.kind = FlatBspNodeKind(def.axis());
    plan.split = def.coord();
    return plan;
  }
  RoundingGuard g;
  const PreparedPlane pp = prepare_plane(g, soup, def);
  int sign = 0;
  const int axis = exact_axis(pp, sign);
  if (axis >= 0 && double(float(pp.ref[axis])) == pp.ref[axis]) {
    // value = n_k·(x_k − r_k): the plane x_k = r_k, negative side below iff n_k > 0.
    plan.kind = FlatBspNodeKind(axis);
    plan.split = float(pp.ref[axis]);
    plan.swap = sign < 0;
    return plan;
  }
  const std::vector<IntervalBox> boxes = vertex_boxes(cell);
  plan.kind = FlatBspNodeKind::Plane;
  plan.plane = float_plane_bound(g, pp, boxes);
  if (!std::isfinite(plan.plane.eps) || !std::isfinite(plan.plane.d))
    throw UsageError("the BSP's float planes overflow for this scene: a split plane's offset or error bound is not "
                     "finite with coordinates this close to the float range's end (about 1e38 and above); trace it "
                     "with kd, bvh8 or brute-certified, which take any finite scene (docs/certified-epsilons.md)");
  return plan;
}

/// Largest distance between two vertex enclosures of a cell (approximate).
double cell_diameter(const Cell& cell) {
  const Box3d b = cell.bounds();
  return length(b.diagonal());
}

/// Emits the subtree of exact node `i` depth-first, first child adjacent
/// (after the tail slot of a plane node).
void emit(const BspTree& exact, const std::vector<NodePlan>& plans, std::uint32_t i,
          FlatBspTree& out) {
  const BspNode& n = exact.nodes()[i];
  const std::uint32_t self = std::uint32_t(out.nodes.size());
  out.nodes.emplace_back();
  if (n.is_leaf()) {
    const std::uint32_t offset = std::uint32_t(out.prims.size());
    const auto tris = exact.leaf_triangles(i);
    out.prims.insert(out.prims.end(), tris.begin(), tris.end());
    out.nodes[self] = FlatBspNode::make_leaf(offset, std::uint32_t(tris.size()));
    return;
  }
  const NodePlan& p = plans[i];
  if (p.kind == FlatBspNodeKind::Plane) out.nodes.push_back(
      FlatBspNode::make_plane_tail(p.plane.d, p.plane.eps));
  emit(exact, plans, p.swap ? n.b : n.a, out);
  const std::uint32_t second = std::uint32_t(out.nodes.size());
  if (second > FlatBspNode::kMaxIndex) throw UsageError("flatten_bsp: too many nodes");
  emit(exact, plans, p.swap ? n.a : n.b, out);
  if (p.kind == FlatBspNodeKind::Plane) {
    const float normal[3] = {p.plane.n[0], p.plane.n[1], p.plane.n[2]};
    out.nodes[self] = FlatBspNode::make_plane_head(normal, second);
  } else {
    out.nodes[self] = FlatBspNode::make_kd(int(p.kind), p.split, second);
  }
}

void fill_report(const FlatBspTree& flat, const std::vector<NodePlan>& plans,
                 const std::vector<double>& diam, FlattenReport& r) {
  const FlatBspStats s = flat_bsp_stats(flat);
  r.plane_nodes = s.plane_nodes;
  r.kd_nodes = s.kd_nodes;
  r.leaves = s.leaves;
  for (int k = 0; k < 3; ++k)
    r.scene_scale = std::max({r.scene_scale, std::fabs(double(flat.bounds.lo[k])),
                              std::fabs(double(flat.bounds.hi[k]))});
  double sum = 0.0;
  for (std::size_t i = 0; i < plans.size(); ++i) {
    if (plans[i].kind != FlatBspNodeKind::Plane) continue;
    const double e = plans[i].plane.eps;
    sum += e;
    r.max_eps = std::max(r.max_eps, e);
    if (diam[i] > 0) r.max_eps_rel_cell = std::max(r.max_eps_rel_cell, e / diam[i]);
  }
  r.mean_eps = r.plane_nodes ? sum / double(r.plane_nodes) : 0.0;
}

}  // namespace

FloatPlane flat_plane_of(const TriangleSoup& soup, PlaneDef plane, const Cell& cell) {
  RoundingGuard g;
  const PreparedPlane pp = prepare_plane(g, soup, plane);
  const std::vector<IntervalBox> boxes = vertex_boxes(cell);
  return float_plane_bound(g, pp, boxes);
}

FlatBspTree flatten_bsp(const TriangleSoup& soup, const BspTree& exact, FlattenReport* report) {
  const IeeeScope ieee;  // the plane bounds assume IEEE arithmetic (fp_env.h)
  const auto start = std::chrono::steady_clock::now();
  try {
    exact.validate(soup.size(), &soup);
  } catch (const std::logic_error& e) {
    throw UsageError(std::string("flatten_bsp: exact tree is not valid: ") + e.what());
  }
  const std::vector<std::uint32_t> depth = exact.depths();
  if (*std::max_element(depth.begin(), depth.end()) >= std::uint32_t(kBspMaxDepth))
    throw UsageError("flatten_bsp: tree deeper than " + std::to_string(kBspMaxDepth) + " levels");
  std::vector<NodePlan> plans(exact.nodes().size());
  std::vector<double> diam(exact.nodes().size(), 0.0);
  std::size_t kd_from_planes = 0;
  ExactStats stats;
  exact.for_each_cell(
      soup,
      [&](std::uint32_t i, const Cell& cell) {
        if (exact.nodes()[i].is_leaf()) return;
        const PlaneDef def = exact.plane_of(i);
        plans[i] = plan_node(soup, def, cell);
        if (!def.is_kd() && plans[i].kind != FlatBspNodeKind::Plane) ++kd_from_planes;
        if (report) diam[i] = cell_diameter(cell);
      },
      &stats);
  FlatBspTree flat;
  flat.bounds = exact.root_box();
  flat.triangle_count = std::uint32_t(soup.size());
  flat.nodes.reserve(exact.nodes().size());
  flat.prims.reserve(exact.triangle_refs().size());
  emit(exact, plans, 0, flat);
  if (report) {
    *report = FlattenReport{};
    fill_report(flat, plans, diam, *report);
    report->kd_from_planes = kd_from_planes;
    report->exact = stats;
    report->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return flat;
}

}  // namespace bsprt
