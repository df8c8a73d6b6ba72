#pragma once
/// \file plane_formula.h
/// The plane a stored PlaneDef stands for, written once over the number type,
/// the way CGAL passes its kernel as a template parameter: double for steering
/// (plane.cpp), CGAL::Interval_nt for the filter (exact_side.cpp), CGAL::Mpzf
/// for the exact stage (exact_eval.cpp). Every value is a polynomial in the
/// input floats, so an exact NT gives the exact plane:
///   kd on axis a:   n = e_a,                       through (coord on a, 0 elsewhere)
///   face of t:      n = (p1 − p0) × (p2 − p0),     through p0
///   edge k of t:    n = n_face × (a1 − a0),        through a0 = p_k, a1 = p_(k+1 mod 3)
/// (edge planes contain the edge and are orthogonal to the face; Ize, Wald,
/// Parker, RT 2008, §3). The verifier (verify/verify_geometry.cpp) keeps its own
/// copy on purpose: it must share no arithmetic with the builder.

#include "bsprt/vec3.h"
#include "geometry/core/triangle_soup.h"
#include "robust/plane.h"

namespace bsprt {

/// Unnormalised normal n and a float point the plane passes through; the
/// plane is n·(x − through) = 0.
template <typename NT>
struct PlaneFormula {
  Vec3<NT> n;
  Vec3f through;
};

/// The formula of the stored plane `p` over `soup`, in NT (constructible from double).
template <typename NT>
PlaneFormula<NT> plane_formula(const TriangleSoup& soup, PlaneDef p) {
  PlaneFormula<NT> f{Vec3<NT>(NT(0.0), NT(0.0), NT(0.0)), Vec3f(0.0f, 0.0f, 0.0f)};
  if (p.is_kd()) {
    f.n[p.axis()] = NT(1.0);
    f.through[p.axis()] = p.coord();
    return f;
  }
  auto at = [](const Vec3f& c) { return Vec3<NT>(NT(double(c.x)), NT(double(c.y)), NT(double(c.z))); };
  const std::uint32_t t = p.tri();
  const Vec3<NT> p0 = at(soup.corner(t, 0)), p1 = at(soup.corner(t, 1)), p2 = at(soup.corner(t, 2));
  f.n = cross(p1 - p0, p2 - p0);
  f.through = soup.corner(t, 0);
  if (p.kind == PlaneKind::Edge) {
    const int k = p.edge_index();
    f.n = cross(f.n, at(soup.corner(t, (k + 1) % 3)) - at(soup.corner(t, k)));
    f.through = soup.corner(t, k);
  }
  return f;
}

}  // namespace bsprt
