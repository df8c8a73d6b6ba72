#pragma once
/// \file plane.h
/// Planes stored by the input data that defines them (docs/bsp-build.md "Exact
/// arithmetic scheme"; Ize, Wald, Parker, "Ray Tracing with the BSP Tree", RT 2008, §3:
/// the candidate planes are a triangle's face plane, the planes through its edges
/// orthogonal to the face, and axis-aligned planes). A PlaneDef never holds a
/// rounded coefficient: its exact coefficients are polynomials in the scene's
/// float coordinates, evaluated by robust/exact_side.h.
///
/// Orientation (the sign convention every part of bsprt shares):
///   value(p) = n · (p − r), with
///   - Kd (axis a, float c):       n = e_a,                         r = c·e_a
///   - Face (triangle t, corners p0 p1 p2):  n = (p1 − p0) × (p2 − p0),      r = p0
///   - Edge (triangle t, edge k: corner k → corner k+1 mod 3):
///                                 n = n_face × (p_{k+1} − p_k),     r = p_k
/// The left (negative) child of a split is the closed half-space value ≤ 0, the
/// right child value ≥ 0. The edge plane's normal points into the triangle.

#include <compare>
#include <cstdint>
#include <cstring>

#include "geometry/core/triangle_soup.h"
#include "bsprt/vec3.h"

namespace bsprt {

/// What defines a plane.
enum class PlaneKind : std::uint8_t {
  Kd = 0,    ///< axis-aligned: an axis and a float coordinate
  Face = 1,  ///< the plane of a (non-degenerate) triangle
  Edge = 2,  ///< through a triangle's edge, orthogonal to its face (paper §3)
};

/// A plane by its defining input data. 8 bytes, trivially copyable, ordered and
/// hashable by key(); written verbatim into tree files (bsp_file.h).
///
///   offset size field
///   0      1    kind (PlaneKind)
///   1      1    sub: Kd → axis 0..2; Edge → edge k 0..2; Face → 0
///   2      2    reserved (0)
///   4      4    data: Kd → IEEE-754 bits of the float coordinate; else triangle id
struct PlaneDef {
  PlaneKind kind = PlaneKind::Kd;
  std::uint8_t sub = 0;
  std::uint16_t reserved = 0;
  std::uint32_t data = 0;

  /// The plane x_axis = coord (coord −0 is stored as +0 so equal planes compare equal).
  static PlaneDef kd(int axis, float coord) {
    PlaneDef p;
    p.kind = PlaneKind::Kd;
    p.sub = static_cast<std::uint8_t>(axis);
    const float c = coord == 0.0f ? 0.0f : coord;
    std::memcpy(&p.data, &c, sizeof c);
    return p;
  }
  /// The face plane of triangle `tri`.
  static PlaneDef face(std::uint32_t tri) {
    PlaneDef p;
    p.kind = PlaneKind::Face;
    p.data = tri;
    return p;
  }
  /// The plane through edge k (corner k → k+1) of `tri`, orthogonal to its face.
  static PlaneDef edge(std::uint32_t tri, int k) {
    PlaneDef p;
    p.kind = PlaneKind::Edge;
    p.sub = static_cast<std::uint8_t>(k);
    p.data = tri;
    return p;
  }

  bool is_kd() const { return kind == PlaneKind::Kd; }
  /// Axis of a Kd plane.
  int axis() const { return sub; }
  /// Coordinate of a Kd plane.
  float coord() const {
    float c;
    std::memcpy(&c, &data, sizeof c);
    return c;
  }
  /// Triangle of a Face or Edge plane.
  std::uint32_t tri() const { return data; }
  /// Edge index k of an Edge plane.
  int edge_index() const { return sub; }
  /// A total order / hash key (equal keys ⇔ equal definitions).
  std::uint64_t key() const {
    return (std::uint64_t(kind) << 56) | (std::uint64_t(sub) << 48) | data;
  }
  bool operator==(const PlaneDef& o) const { return key() == o.key(); }
  std::strong_ordering operator<=>(const PlaneDef& o) const { return key() <=> o.key(); }
};
static_assert(sizeof(PlaneDef) == 8, "PlaneDef is written verbatim into tree files");

/// A double approximation of a plane, n·p + d with |n| = 1: for steering only
/// (SAH areas, sphere tests with margins, candidate ordering), never for decisions.
struct ApproxPlane {
  Vec3d n;
  double d = 0;
  double eval(const Vec3d& p) const { return dot(n, p) + d; }
};

/// The normalized double approximation of `p` (same orientation as the exact plane).
ApproxPlane approx_plane(const TriangleSoup& soup, PlaneDef p);

/// True when the plane's definition is usable with `soup`: triangle id in range,
/// axis/edge index 0..2, finite Kd coordinate. (Degeneracy is checked separately.)
bool plane_in_range(const TriangleSoup& soup, PlaneDef p);

}  // namespace bsprt
