#pragma once
/// \file cell.h
/// Convex polytope cells of the general BSP tree (Ize, Wald, Parker, RT 2008,
/// §3.1: every node's region is the convex polytope cut out by its ancestors'
/// planes, starting from the scene's bounding box).
///
/// Representation (purely combinatorial, decided exactly): a vertex is an
/// ExactPoint (three stored planes) plus the sorted list of the cell's facet
/// planes through it. Two vertices span an edge iff they share two facets (in a
/// convex polytope whose facet planes are pairwise distinct, the only vertices on
/// the line of two facets are that edge's endpoints). Splitting by a plane P:
/// vertices are classified exactly; an edge whose endpoints lie strictly on
/// opposite sides gives a new vertex (its two facets, P) — again three stored
/// planes, so constructions never chain; vertices on P go to both children.
/// A split is only accepted when P has vertices strictly on both sides, so both
/// children have interiors and facet planes stay distinct.
///
/// Areas, volumes and facet loops are double approximations: they steer the SAH.

#include <vector>

#include "geometry/core/triangle_soup.h"
#include "bsprt/vec3.h"
#include "robust/exact_side.h"
#include "robust/plane.h"

namespace bsprt {

/// A cell vertex: the exact point and the facet planes through it (sorted by key).
struct CellVertex {
  ExactPoint point;
  std::vector<PlaneDef> facets;
};

/// One facet as an ordered loop of approximate vertex positions, counter-clockwise
/// seen from outside; `vec_area` is its outward vector area.
struct FacetLoop {
  PlaneDef plane;
  std::vector<Vec3d> pts;
  Vec3d vec_area;
};

/// A convex polytope cell (see the file comment).
class Cell {
 public:
  Cell() = default;

  /// The box `b` as a cell of six Kd facets (b must have lo < hi on every axis).
  static Cell box(const Box3f& b);

  /// Vertices with their exact points and incident facets.
  const std::vector<CellVertex>& vertices() const { return vertices_; }
  /// Facet planes (sorted by key).
  const std::vector<PlaneDef>& facets() const { return facets_; }
  /// True when every facet is a Kd plane (the cell is an axis-aligned box).
  bool is_box() const;
  /// Bounds of the vertices' interval enclosures (conservative).
  Box3d bounds() const;

  /// Splits exactly by `plane` into the closed halves value ≤ 0 (`left`) and
  /// value ≥ 0 (`right`). Returns false and leaves the outputs untouched when the
  /// plane does not have vertices strictly on both sides.
  bool split(const RoundingGuard& g, const TriangleSoup& soup, const PreparedPlane& plane,
             Cell& left, Cell& right, ExactStats& stats) const;

  /// Facet loops in double (steering: SAH areas).
  std::vector<FacetLoop> facet_loops(const TriangleSoup& soup) const;
  /// Approximate surface area.
  double area(const TriangleSoup& soup) const;
  /// Approximate volume.
  double volume(const TriangleSoup& soup) const;

 private:
  std::vector<CellVertex> vertices_;
  std::vector<PlaneDef> facets_;
};

/// Approximate surface areas of the two closed halves of a cell (given by its
/// facet loops) cut by `p`: the facets' parts plus the cross-section, whose area
/// is the norm of the summed vector areas (the halves' surfaces are closed).
void split_areas(const std::vector<FacetLoop>& loops, const ApproxPlane& p, double& left,
                 double& right);

/// Total area of facet loops.
double loops_area(const std::vector<FacetLoop>& loops);

}  // namespace bsprt
