/// \file plane.cpp
/// Double approximations of stored planes (steering only) and range checks.
#include "robust/plane.h"

#include <cmath>

#include "robust/plane_formula.h"

namespace bsprt {

ApproxPlane approx_plane(const TriangleSoup& soup, PlaneDef p) {
  ApproxPlane a;
  const PlaneFormula<double> f = plane_formula<double>(soup, p);
  if (p.is_kd()) {
    a.n = f.n;
    a.d = -double(p.coord());
    return a;
  }
  const double len = length(f.n);
  a.n = len > 0 ? f.n / len : Vec3d(0, 0, 0);
  a.d = -dot(a.n, Vec3d(f.through));
  return a;
}

bool plane_in_range(const TriangleSoup& soup, PlaneDef p) {
  if (p.reserved != 0) return false;
  switch (p.kind) {
    case PlaneKind::Kd: return p.sub < 3 && std::isfinite(p.coord());
    case PlaneKind::Face: return p.sub == 0 && p.data < soup.size();
    case PlaneKind::Edge: return p.sub < 3 && p.data < soup.size();
  }
  return false;
}

}  // namespace bsprt
