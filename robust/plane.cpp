/// \file plane.cpp
/// Double approximations of stored planes (steering only) and range checks.
#include "robust/plane.h"

#include <cmath>

namespace bsprt {

namespace {
Vec3d corner_d(const TriangleSoup& soup, std::uint32_t t, int k) { return Vec3d(soup.corner(t, k)); }
}  // namespace

ApproxPlane approx_plane(const TriangleSoup& soup, PlaneDef p) {
  ApproxPlane a;
  if (p.is_kd()) {
    a.n = Vec3d(0, 0, 0);
    a.n[p.axis()] = 1.0;
    a.d = -double(p.coord());
    return a;
  }
  const std::uint32_t t = p.tri();
  const Vec3d p0 = corner_d(soup, t, 0), p1 = corner_d(soup, t, 1), p2 = corner_d(soup, t, 2);
  Vec3d n = cross(p1 - p0, p2 - p0);
  Vec3d r = p0;
  if (p.kind == PlaneKind::Edge) {
    const int k = p.edge_index();
    const Vec3d a0 = corner_d(soup, t, k), a1 = corner_d(soup, t, (k + 1) % 3);
    n = cross(n, a1 - a0);
    r = a0;
  }
  const double len = length(n);
  a.n = len > 0 ? n / len : Vec3d(0, 0, 0);
  a.d = -dot(a.n, r);
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
