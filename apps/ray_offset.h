#pragma once
/// \file ray_offset.h
/// Robust spawning of secondary rays (pbrt-v4, "Robust Spawned Ray Origins",
/// Pharr, Jakob, Humphreys, 4th ed. Sec. 6.8.6): the hit point is recomputed
/// from its barycentrics together with a bound on its rounding error, and the
/// new origin is pushed off the surface along the normal by just that bound,
/// then rounded away from the surface. No scene-size constant, so it holds at
/// scale 1e-4 as at 1e5.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "bsprt/ray.h"
#include "bsprt/vec3.h"

namespace bsprt {

/// gamma_n = n u / (1 - n u), u = 2^-24 (float unit roundoff): the bound on
/// the relative error of n chained float operations (Higham; pbrt-v4 Eq. 6.22).
constexpr float gamma_f(int n) {
  constexpr float u = std::numeric_limits<float>::epsilon() * 0.5f;
  return (float(n) * u) / (1.0f - float(n) * u);
}

/// A surface point, a bound on each coordinate's absolute error, and the
/// triangle's extent around it (for the intersection test's own rounding).
struct SurfacePoint {
  Vec3f p;
  Vec3f error;
  float extent = 0.0f;  ///< max_i |v_i - p| (max norm)
};

/// The hit point (1-u-v) v0 + u v1 + v v2 with its error bound: pbrt-v4's
/// Triangle::InteractionFromIntersection uses gamma(7) * sum |b_i v_i|.
inline SurfacePoint surface_point(const std::array<Vec3f, 3>& tri, float u, float v) {
  const float b0 = 1.0f - u - v;
  SurfacePoint s;
  s.p = tri[0] * b0 + tri[1] * u + tri[2] * v;
  s.error = (abs(tri[0] * b0) + abs(tri[1] * u) + abs(tri[2] * v)) * gamma_f(7);
  for (const Vec3f& c : tri) {
    const Vec3f e = abs(c - s.p);
    s.extent = std::max(s.extent, std::max(e.x, std::max(e.y, e.z)));
  }
  return s;
}

/// An origin for a ray leaving `sp` in direction `w`, offset along the
/// geometric normal `n` by the error bound (pbrt-v4 OffsetRayOrigin), plus a
/// margin for the rounding of the watertight test itself on a ray starting
/// at its own triangle: its t is computed from vertices relative to the
/// origin, so its error scales with the triangle's extent around p (pbrt-v4
/// rejects t below the same kind of bound, deltaT, inside its triangle test;
/// we keep the test exact-by-construction and move the origin instead).
inline Vec3f offset_ray_origin(const SurfacePoint& sp, const Vec3f& n, const Vec3f& w) {
  const float d = dot(abs(n), sp.error) + gamma_f(32) * sp.extent;
  Vec3f offset = n * d;
  if (dot(w, n) < 0) offset = -offset;
  Vec3f po = sp.p + offset;
  for (int i = 0; i < 3; ++i) {  // round away from p so the offset survives rounding
    if (offset[i] > 0) po[i] = std::nextafter(po[i], std::numeric_limits<float>::infinity());
    else if (offset[i] < 0) po[i] = std::nextafter(po[i], -std::numeric_limits<float>::infinity());
  }
  return po;
}

/// A ray leaving `sp` in direction `w`: the offset origin, and tnear = the
/// smallest positive float, so a hit at exactly t = 0 (an origin lying exactly
/// on its own surface, where the error bound is 0) is not reported (pbrt-v4's
/// triangle test asks t > 0 for the same reason).
inline Ray spawn_ray(const SurfacePoint& sp, const Vec3f& n, const Vec3f& w) {
  Ray r;
  r.org = offset_ray_origin(sp, n, w);
  r.dir = w;
  r.tnear = std::numeric_limits<float>::denorm_min();
  return r;
}

}  // namespace bsprt
