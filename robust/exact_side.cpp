/// \file exact_side.cpp
/// The filtered stage of the side tests (exact_side.h): interval enclosures of
/// plane normals and of triple-plane intersection points with
/// CGAL::Interval_nt<false> (the caller holds a RoundingGuard), symbolic zeros
/// from the definitions, and the exact fallback (exact_eval.cpp) when the
/// interval contains 0.
#include <CGAL/Interval_nt.h>

#include "geometry/core/check.h"
#include "robust/exact_side.h"
#include "robust/plane_formula.h"

namespace bsprt {

namespace {

using IA = CGAL::Interval_nt<false>;
using IV = Vec3<IA>;  // cross and dot: bsprt/vec3.h, written once over the number type

/// Interval normal and exact reference point of a stored plane (plane_formula.h).
void plane_normal(const TriangleSoup& soup, PlaneDef p, IV& n, std::array<double, 3>& ref) {
  const PlaneFormula<IA> f = plane_formula<IA>(soup, p);
  n = f.n;
  ref = {double(f.through.x), double(f.through.y), double(f.through.z)};
}

int certain_sign(const IA& v) {
  if (v.inf() > 0) return 1;
  if (v.sup() < 0) return -1;
  if (v.inf() == 0 && v.sup() == 0) return 0;
  return 2;  // uncertain
}

}  // namespace

PreparedPlane prepare_plane(const RoundingGuard&, const TriangleSoup& soup, PlaneDef p) {
  PreparedPlane q;
  q.def = p;
  IV n;
  plane_normal(soup, p, n, q.ref);
  for (int i = 0; i < 3; ++i) {
    q.n_lo[i] = n[i].inf();
    q.n_hi[i] = n[i].sup();
  }
  if (!p.is_kd()) {
    const std::uint32_t t = p.tri();
    if (p.kind == PlaneKind::Face) {
      q.on_points = {soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2)};
      q.on_count = 3;
    } else {
      q.on_points[0] = soup.corner(t, p.edge_index());
      q.on_points[1] = soup.corner(t, (p.edge_index() + 1) % 3);
      q.on_count = 2;
    }
  }
  q.approx = approx_plane(soup, p);
  return q;
}

ExactPoint corner_point(const TriangleSoup& soup, std::uint32_t t, int k) {
  ExactPoint e;
  e.def = {PlaneDef::face(t), PlaneDef::edge(t, (k + 2) % 3), PlaneDef::edge(t, k)};
  const Vec3f& c = soup.corner(t, k);
  for (int i = 0; i < 3; ++i) e.box.lo[i] = e.box.hi[i] = double(c[i]);
  return e;
}

ExactPoint make_point(const RoundingGuard&, const TriangleSoup& soup, PlaneDef a, PlaneDef b,
                      PlaneDef c, ExactStats& stats) {
  ExactPoint e;
  e.def = {a, b, c};
  // Cramer's rule relative to the exact reference point o of plane a: planes
  // n_i·(p − o) + d_i = 0 with d_i = −n_i·(r_i − o), so far-away scenes keep
  // their precision.
  std::array<IV, 3> n;
  std::array<std::array<double, 3>, 3> r;
  for (int i = 0; i < 3; ++i) plane_normal(soup, e.def[i], n[i], r[i]);
  const std::array<double, 3>& o = r[0];
  std::array<IA, 3> d;
  for (int i = 0; i < 3; ++i) {
    const IV ro(IA(r[i][0]) - o[0], IA(r[i][1]) - o[1], IA(r[i][2]) - o[2]);
    d[i] = -dot(n[i], ro);
  }
  const IV bc = cross(n[1], n[2]), ca = cross(n[2], n[0]), ab = cross(n[0], n[1]);
  const IA den = dot(n[0], bc);
  if (den.inf() > 0 || den.sup() < 0) {
    for (int i = 0; i < 3; ++i) {
      const IA x = o[i] + (-(d[0] * bc[i] + d[1] * ca[i] + d[2] * ab[i])) / den;
      e.box.lo[i] = x.inf();
      e.box.hi[i] = x.sup();
    }
  } else {
    ++stats.exact_points;
    e.box = exact_enclosure(soup, e.def);
  }
  for (const PlaneDef& p : e.def)
    if (p.is_kd()) e.box.lo[p.axis()] = e.box.hi[p.axis()] = double(p.coord());
  return e;
}

int side(const RoundingGuard&, const TriangleSoup& soup, const PreparedPlane& plane,
         const ExactPoint& p, ExactStats& stats) {
  if (p.defined_by(plane.def)) {
    ++stats.symbolic;
    return 0;
  }
  const bool exact_coords = p.box.is_point();
  if (plane.def.is_kd()) {
    const int a = plane.def.axis();
    const double c = plane.ref[a];
    ++stats.filter_calls;
    if (p.box.lo[a] > c) return 1;
    if (p.box.hi[a] < c) return -1;
    if (p.box.lo[a] == c && p.box.hi[a] == c) return 0;
    ++stats.exact_fallbacks;
    return exact_side_at(soup, plane.def, p.def);
  }
  if (exact_coords) {
    for (int i = 0; i < plane.on_count; ++i) {
      const Vec3f& q = plane.on_points[i];
      if (double(q.x) == p.box.lo[0] && double(q.y) == p.box.lo[1] && double(q.z) == p.box.lo[2]) {
        ++stats.symbolic;
        return 0;
      }
    }
  }
  ++stats.filter_calls;
  IA v(0.0);
  for (int i = 0; i < 3; ++i)
    v += IA(plane.n_lo[i], plane.n_hi[i]) * (IA(p.box.lo[i], p.box.hi[i]) - plane.ref[i]);
  const int s = certain_sign(v);
  if (s != 2) return s;
  ++stats.exact_fallbacks;
  if (exact_coords) return exact_side_at(soup, plane.def, p.box.lo);
  return exact_side_at(soup, plane.def, p.def);
}

}  // namespace bsprt
