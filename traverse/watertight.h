#pragma once
/// \file watertight.h
/// Scalar watertight ray/triangle test: Woop, Benthin & Wald, "Watertight
/// Ray/Triangle Intersection", JCGT 2(1), 2013. The ray is sheared so that it
/// becomes the +z axis from the origin; the 2D edge functions of the sheared
/// triangle are computed so that two triangles sharing an edge get exactly
/// opposite values, hence no ray slips between them (paper Sec. 3-4).
///
/// Conventions (shared/formats.md): both sides hit (no backface culling), a hit
/// needs t in [tnear, tfar], u and v are the barycentrics of v1 and v2 (hit
/// point = (1-u-v) v0 + u v1 + v v2). Invalid rays (is_valid false) miss.
/// Degenerate triangles are skipped by callers (TriangleSoup::is_degenerate):
/// a collinear triangle may still produce a float hit here.
///
/// The functions are inline for leaf loops of the kd and BSP traversals. They
/// live in the ISA inline namespace of simd.h, so including this header from a
/// per-ISA kernel translation unit is safe. Results are bit-identical on every
/// ISA (products are kept out of FMAs with no_fma), and the packet test of
/// watertight_packet.h reproduces them bit for bit.

#include <cstdint>
#include <limits>
#include <optional>
#include <utility>

#include "bsprt/ray.h"
#include "traverse/simd/simd.h"

namespace bsprt {

/// Per-ray constants of the watertight test (paper Fig. 1, first part): kz is
/// the axis where |dir| is largest, kx and ky the other two (swapped when
/// dir[kz] < 0 to keep the winding), and the shear sx = dir[kx]/dir[kz],
/// sy = dir[ky]/dir[kz], sz = 1/dir[kz]. Plain data, make it once per ray.
struct WatertightRay {
  Vec3f org;                                              ///< ray origin
  int kx = 0, ky = 1, kz = 2;                             ///< axis permutation
  float sx = 0.0f, sy = 0.0f, sz = 1.0f;                  ///< shear and scale
  float tnear = 0.0f;                                     ///< segment start
  float tfar = std::numeric_limits<float>::infinity();    ///< segment end
  bool valid = false;                                     ///< is_valid(ray); false = always miss
};

/// A hit of one triangle: distance and barycentrics of v1 and v2.
struct TriangleHit {
  float t;  ///< ray parameter, in units of dir
  float u;  ///< barycentric of v1
  float v;  ///< barycentric of v2
};

inline namespace BSPRT_ISA_NAMESPACE {

/// Precomputes the shear of `ray` (paper Fig. 1, lines 1-12) into `r`, field
/// by field. Invalid rays get valid = false and then miss every triangle.
/// Kernels that make the shear lazily, into a WatertightRay declared before
/// (the BVH8's first leaf, the BSP's per-ray leaf constants), call this rather
/// than assigning watertight_precompute's result: GCC built that result on the
/// stack and copied it with loads wider than the stores that made it, which
/// cannot be forwarded (perf, `bvh8` on sponza's atrium camera rays: 3 % of
/// the samples on that copy).
inline void watertight_init(const Ray& ray, WatertightRay& r) {
  r.org = ray.org;
  r.tnear = ray.tnear;
  r.tfar = ray.tfar;
  r.valid = is_valid(ray);
  r.kx = 0, r.ky = 1, r.kz = 2;
  r.sx = 0.0f, r.sy = 0.0f, r.sz = 1.0f;
  if (!r.valid) return;
  r.kz = max_axis(ray.dir);
  r.kx = r.kz == 2 ? 0 : r.kz + 1;
  r.ky = r.kx == 2 ? 0 : r.kx + 1;
  if (ray.dir[r.kz] < 0.0f) std::swap(r.kx, r.ky);
  r.sx = ray.dir[r.kx] / ray.dir[r.kz];
  r.sy = ray.dir[r.ky] / ray.dir[r.kz];
  r.sz = 1.0f / ray.dir[r.kz];
}

/// The same, returned.
inline WatertightRay watertight_precompute(const Ray& ray) {
  WatertightRay r;
  watertight_init(ray, r);
  return r;
}

/// The paper's fallback (Sec. 3, "fallback to test against edges using double
/// precision"): when a float edge function is exactly 0, all three are redone
/// in double, where the products of floats are exact, so the sign is exact.
/// Shared by the scalar and packet tests so both round identically.
inline void watertight_edges_double(float ax, float ay, float bx, float by, float cx, float cy,
                                    float& u, float& v, float& w) {
  u = float(double(cx) * double(by) - double(cy) * double(bx));
  v = float(double(ax) * double(cy) - double(ay) * double(cx));
  w = float(double(bx) * double(ay) - double(by) * double(ax));
}

/// Watertight test of the precomputed ray against triangle (v0, v1, v2): the
/// hit when the ray meets it at t in [tnear, tfar] (t finite), else nullopt.
/// Both sides hit; det == 0 (ray parallel to the plane, or a degenerate
/// projection) misses. u, v are the barycentrics of v1 and v2.
inline std::optional<TriangleHit> intersect_watertight(const WatertightRay& r, const Vec3f& v0,
                                                       const Vec3f& v1, const Vec3f& v2,
                                                       float tnear, float tfar) {
  if (!r.valid) return std::nullopt;
  // Vertices relative to the origin, sheared (paper Fig. 1, lines 14-25).
  const Vec3f a = v0 - r.org, b = v1 - r.org, c = v2 - r.org;
  const float az_ = a[r.kz], bz_ = b[r.kz], cz_ = c[r.kz];
  const float ax = a[r.kx] - no_fma(r.sx * az_), ay = a[r.ky] - no_fma(r.sy * az_);
  const float bx = b[r.kx] - no_fma(r.sx * bz_), by = b[r.ky] - no_fma(r.sy * bz_);
  const float cx = c[r.kx] - no_fma(r.sx * cz_), cy = c[r.ky] - no_fma(r.sy * cz_);
  // Scaled barycentrics: U for v0, V for v1, W for v2 (lines 27-29).
  float u = no_fma(cx * by) - no_fma(cy * bx);
  float v = no_fma(ax * cy) - no_fma(ay * cx);
  float w = no_fma(bx * ay) - no_fma(by * ax);
  if (u == 0.0f || v == 0.0f || w == 0.0f) watertight_edges_double(ax, ay, bx, by, cx, cy, u, v, w);
  // Edge tests without backface culling: all >= 0 or all <= 0 (line 47).
  if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return std::nullopt;
  const float det = u + v + w;
  if (det == 0.0f) return std::nullopt;
  // Hit distance from the scaled z of the vertices (lines 53-57). Dividing
  // here (instead of the paper's deferred compare) gives a correctly rounded t
  // and an exact [tnear, tfar] test. NaN from overflow fails the compare.
  const float tz = no_fma(u * (r.sz * az_)) + no_fma(v * (r.sz * bz_)) + no_fma(w * (r.sz * cz_));
  const float t = tz / det;
  if (!(t >= tnear && t <= tfar && t < std::numeric_limits<float>::infinity())) return std::nullopt;
  const float rcp = 1.0f / det;
  return TriangleHit{t, v * rcp, w * rcp};
}

/// As above with the ray's own segment [r.tnear, r.tfar].
inline std::optional<TriangleHit> intersect_watertight(const WatertightRay& r, const Vec3f& v0,
                                                       const Vec3f& v1, const Vec3f& v2) {
  return intersect_watertight(r, v0, v1, v2, r.tnear, r.tfar);
}

/// Leaf-loop helper: tests triangle `prim` and replaces `hit` when the new t is
/// in [r.tnear, r.tfar] and strictly below hit.t (ties keep the earlier
/// triangle). Returns true when `hit` changed.
inline bool intersect_watertight_closest(const WatertightRay& r, const Vec3f& v0, const Vec3f& v1,
                                         const Vec3f& v2, std::uint32_t prim, Hit& hit) {
  const std::optional<TriangleHit> h = intersect_watertight(r, v0, v1, v2, r.tnear, r.tfar);
  if (!h || !(h->t < hit.t)) return false;
  hit.t = h->t;
  hit.prim = prim;
  hit.u = h->u;
  hit.v = h->v;
  return true;
}

}  // namespace BSPRT_ISA_NAMESPACE
}  // namespace bsprt
