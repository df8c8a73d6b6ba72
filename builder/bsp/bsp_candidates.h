#pragma once
/// \file bsp_candidates.h
/// Candidate split planes of one BSP node and their SAH costs (Ize, Wald,
/// Parker, RT 2008, §3.2–§4; docs/bsp-build.md "Costs"):
///  - kd candidates: axis-aligned float planes at the clipped triangles' bounds
///    (lower bound rounded down, upper rounded up to float), counted for all
///    planes of an axis by one sweep over sorted bounds (O(N log N));
///  - BSP candidates: each triangle's face plane and three edge planes, counted
///    exactly with the bounding-sphere hierarchy (bsh.h).
/// Child areas are the real polytope areas (cell.h, double: they steer).

#include <vector>

#include "builder/bsp/bsh.h"
#include "builder/bsp/bsp_config.h"
#include "robust/cell.h"
#include "robust/exact_polygon.h"

namespace bsprt {

/// One evaluated candidate.
struct Candidate {
  PlaneDef plane;
  double cost = 0;        ///< SAH cost of splitting here
  double area_left = 0;   ///< approximate surface areas of the two child cells
  double area_right = 0;
  double c_trav = 0;      ///< traversal cost of the node this plane would make
  /// By the (conservative) counts, one child would list every triangle of the
  /// node: the only kind of split BspConfig::min_gain limits.
  bool keeps_all = false;
};

/// Whether a split with counts `c` of a node of `n` triangles leaves one child
/// with all of them (coplanar triangles counted on both sides).
inline bool keeps_all(const SplitCount& c, std::size_t n) {
  return c.left + c.both + c.coplanar >= n || c.right + c.both + c.coplanar >= n;
}

/// What the candidate evaluation needs to know about a node.
struct NodeView {
  const Cell& cell;
  const std::vector<ClippedTriangle>& tris;
  std::vector<FacetLoop> loops;  ///< the cell's facet loops (empty for box cells)
  Box3d bounds;                  ///< the cell's bounds (exact for box cells)
  double area = 0;               ///< the cell's surface area
  bool box = false;              ///< the cell is an axis-aligned box
};

/// Prepares a NodeView (facet loops and area) for `cell` and `tris`.
NodeView make_node_view(const TriangleSoup& soup, const Cell& cell,
                        const std::vector<ClippedTriangle>& tris);

/// SAH cost of a split with traversal cost `c_trav`. Coplanar triangles go to
/// both children or, when the config allows, to the cheaper one; `coplanar_left`
/// tells which was chosen.
double sah_cost(const BspConfig& cfg, double c_trav, const SplitCount& n, double area_left,
                double area_right, double area, bool* coplanar_left = nullptr);

/// Appends the valid kd candidates (strictly inside the cell) to `out`; returns
/// how many were added.
std::size_t add_kd_candidates(const NodeView& v, const BspConfig& cfg, std::vector<Candidate>& out);

/// Appends the face/edge candidates that cut the cell, counted exactly.
/// `kd_exists` selects C_BSP = slope·C_isect·(N−2) + C_kd, else the fixed cost.
void add_bsp_candidates(const RoundingGuard& g, const TriangleSoup& soup, const NodeView& v,
                        const BspConfig& cfg, bool kd_exists, std::vector<Candidate>& out,
                        ExactStats& stats);

/// The traversal cost of a BSP node holding n triangles.
double bsp_traversal_cost(const BspConfig& cfg, std::size_t n, bool kd_exists);

}  // namespace bsprt
