#pragma once
/// \file verify_cell.h
/// The verifier's convex cells (verify.h) and triangle pieces, independent of
/// robust/cell.h and robust/exact_polygon.h. A cell is a boundary
/// representation: vertices (each the intersection of three planes of the
/// PlaneTable) and facets (a plane and an outward counter-clockwise vertex
/// loop). Cutting by a plane clips every facet loop (Sutherland–Hodgman), a new
/// vertex on an edge being the intersection of the edge's two facet planes and
/// the cut; the cap facet is chained from the clipped facets' edges on the
/// cut. A piece is T ∩ cell for a triangle T: a convex polygon whose edges are
/// labelled by the line they lie on (an edge of T, or T's face plane ∩ a cut
/// plane), so a new vertex is again built from stored data only.

#include <cstdint>
#include <vector>

#include "verify/verify_geometry.h"

namespace bsprt::vfy {

/// A facet: its plane and vertex loop (outward, counter-clockwise).
struct Facet {
  std::uint32_t plane = 0;
  std::vector<std::uint32_t> loop;
};

/// A convex polytope with positive volume.
struct VCell {
  std::vector<Vtx> verts;
  std::vector<Facet> facets;
};

/// The root box as a cell (8 vertices, 6 facets).
VCell root_cell(const PlaneTable& pt);

/// Outcome of cut_cell.
struct CutResult {
  bool ok = false;           ///< vertices strictly on both sides
  std::uint32_t witness = 0; ///< ok == false: a vertex of the side that has them all
};

/// Cuts `cell` by plane `plane` into left (value ≤ 0) and right (≥ 0). Both
/// children have positive volume when ok. Throws std::logic_error if the facet
/// structure is inconsistent (a bug, never a property of the input).
CutResult cut_cell(const PlaneTable& pt, VCell& cell, std::uint32_t plane, VCell& left, VCell& right,
                   Counters& c);

/// Volume enclosure (interval; divergence theorem over facet fans).
IT volume(const VCell& cell);

/// Label of a piece edge lying on edge k of its triangle.
inline constexpr std::uint32_t kTriEdge = 0x80000000u;

/// T ∩ cell for one triangle, with the rule's status.
struct Piece {
  std::uint32_t tri = 0;
  bool required = true;  ///< the rule requires leaves reached to list it
  bool area = true;      ///< positive area (false: a segment or a point)
  std::vector<Vtx> v;    ///< convex polygon (1, 2 or more vertices)
  std::vector<std::uint32_t> label;  ///< edge i → i+1: kTriEdge|k or a plane id
};

/// The whole triangle (three corners).
Piece root_piece(const TriangleSoup& soup, std::uint32_t tri);

/// What clip_piece found.
struct ClipResult {
  bool left = false, right = false;            ///< touches the closed half
  bool left_area = false, right_area = false;  ///< with positive area
  bool coplanar = false;                       ///< lies in the plane
};

/// Clips `p` by `plane` into `left` (value ≤ 0) and `right` (≥ 0); a side not
/// touched is left empty.
ClipResult clip_piece(const PlaneTable& pt, Piece& p, std::uint32_t plane, Piece& left, Piece& right,
                      Counters& c);

}  // namespace bsprt::vfy
