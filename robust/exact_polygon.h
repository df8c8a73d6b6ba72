#pragma once
/// \file exact_polygon.h
/// A triangle clipped to a cell, T ∩ C, held exactly ("perfect splits": Ize,
/// Wald, Parker, RT 2008, §3.2 classify the clipped triangle, not its bounds).
/// Its vertices are triangle corners or triple intersections of stored planes:
/// (face T, edge plane of T, a cell plane) on T's edges and (face T, two cell
/// planes) inside T. Every polygon edge remembers the plane that cuts it out of
/// T's face plane, so clipping creates (face T, that plane, split plane): never a
/// construction from a construction.
///
/// Signs use T's corners first: f is linear on T, so a point strictly inside an
/// edge with corner signs (a, b) has sign a when a == b, the nonzero one when the
/// other is 0; when all corners agree, so does the whole polygon. Only the rest is
/// evaluated (filtered, exact fallback) per vertex.

#include <cstdint>
#include <vector>

#include "geometry/core/triangle_soup.h"
#include "robust/exact_side.h"

namespace bsprt {

/// Where a polygon vertex lies on its triangle.
enum class PolyLoc : std::uint8_t {
  Corner0, Corner1, Corner2,  ///< a corner of T
  Edge0, Edge1, Edge2,        ///< strictly inside edge k (corner k → k+1)
  Inside,                     ///< elsewhere in T (may still be on T's boundary)
};

/// A vertex of T ∩ C and the plane of the polygon edge that leaves it.
struct PolyVertex {
  ExactPoint point;
  PlaneDef next;
  PolyLoc loc = PolyLoc::Inside;
};

/// T ∩ C: a convex polygon (≥ 3 vertices, positive area), a segment (2) or a
/// point (1). Vertices are extreme points, in order around the polygon.
struct ClippedTriangle {
  std::uint32_t tri = 0;
  std::vector<PolyVertex> verts;
  /// True when the clipped triangle has positive area.
  bool proper() const { return verts.size() >= 3; }
  /// Bounds of the vertices' interval enclosures (conservative).
  Box3d bounds() const;
};

/// Triangle t itself (the root cell contains every triangle).
ClippedTriangle full_triangle(const TriangleSoup& soup, std::uint32_t t);

/// Which closed sides a clipped triangle reaches: a vertex with value < 0, = 0, > 0.
struct SideSummary {
  bool neg = false, zero = false, pos = false;
  /// All vertices on the plane (the clipped triangle lies in it).
  bool coplanar() const { return zero && !neg && !pos; }
};

/// Exact sign of every vertex of `c` against `plane` (into `signs`) and the summary.
SideSummary polygon_signs(const RoundingGuard& g, const TriangleSoup& soup,
                          const PreparedPlane& plane, const ClippedTriangle& c,
                          std::vector<int>& signs, ExactStats& stats);

/// Clips `c` to the closed half-space value ≤ 0 (keep_side < 0) or value ≥ 0
/// (keep_side > 0), given the signs from polygon_signs. May return 0 vertices.
ClippedTriangle clip_polygon(const RoundingGuard& g, const TriangleSoup& soup,
                             const PreparedPlane& plane, const ClippedTriangle& c,
                             const std::vector<int>& signs, int keep_side, ExactStats& stats);

}  // namespace bsprt
