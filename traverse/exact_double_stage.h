#pragma once
/// \file exact_double_stage.h
/// The double stage of the exact leaf test (robust/certified_intersector.h,
/// docs/exact-leaf-test.md, "The double filter"), inline, so that a traversal
/// decides the common triangle in its own loop and calls the exact-decision
/// intersector (a virtual call) only for what this stage leaves open. The
/// certified intersector runs the same functions first, so both decide every
/// triangle with the same IEEE operations (every file that includes this one
/// is compiled with -ffp-contract=off). No CGAL here.
///
/// exact_leaf_staged() gives the answer of LeafIntersector::intersect() bit
/// for bit, counters included: a triangle is decided inline only when the
/// intersector would decide it in its double stage too, and everything else
/// (a sign the filter cannot settle, a t it cannot round, an enclosure that
/// overlaps the nearest hit's) goes to the intersector, one triangle at a
/// time. Test: "staged exact leaf: equals the certified intersector"
/// (tests/test_certified_intersector.cpp).

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <span>

#include "bsprt/ray.h"
#include "traverse/counters.h"
#include "traverse/leaf_intersector.h"
#include "traverse/simd/simd.h"

namespace bsprt::detail {

/// Per-ray constants of the double filter: the watertight test's shear
/// (Woop, Benthin and Wald, JCGT 2013) in double. kz is the axis of the
/// largest |d|, and (kx, ky, kz) is cyclic, or swapped when d[kz] < 0, so the
/// sheared 2D cross products have the signs of the Plücker volumes.
struct ExactRayConst {
  double d[3];             ///< direction
  double ox, oy, oz;       ///< origin components kx, ky, kz
  double abs_d;            ///< |d[kz]|: sheared volumes are the Plücker ones divided by it
  int kx, ky, kz;
  double sx, sy, asx, asy;  ///< d[kx] / d[kz], d[ky] / d[kz] and their magnitudes
};

/// What a stage decided: a miss, a hit (weights of one sign, or a t rounded
/// to float), or nothing (the exact stage must look).
enum class Stage : std::uint8_t { Miss, Hit, Open };

/// Sheared weights of one triangle: w[k] pairs the two corners other than k.
/// s[k] is +1 or -1 where the static bound decides the sign, 2 where it does not.
struct StageWeights {
  double w[3];
  int s[3];
};

inline namespace BSPRT_ISA_NAMESPACE {  // compiled into per-ISA kernels too (simd.h, ODR)

inline ExactRayConst exact_ray_const(const Ray& ray) {
  ExactRayConst f;
  f.d[0] = ray.dir.x, f.d[1] = ray.dir.y, f.d[2] = ray.dir.z;
  const double ax = std::abs(f.d[0]), ay = std::abs(f.d[1]), az = std::abs(f.d[2]);
  f.kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
  f.kx = f.kz == 2 ? 0 : f.kz + 1;
  f.ky = f.kx == 2 ? 0 : f.kx + 1;
  if (f.d[f.kz] < 0) std::swap(f.kx, f.ky);
  const double o[3] = {ray.org.x, ray.org.y, ray.org.z};
  f.ox = o[f.kx], f.oy = o[f.ky], f.oz = o[f.kz];
  const double dz = f.d[f.kz];
  f.abs_d = std::abs(dz);
  f.sx = f.d[f.kx] / dz;
  f.sy = f.d[f.ky] / dz;
  f.asx = std::abs(f.sx);
  f.asy = std::abs(f.sy);
  return f;
}

/// -1, +1 from the double filter, or 2 when |x| <= bound (or x or the bound is NaN).
inline int filtered_sign(double x, double bound) { return x > bound ? 1 : (x < -bound ? -1 : 2); }
/// Two decided signs that differ: the line misses, whatever the third is.
inline bool opposite_signs(int a, int b) { return (a == 1 && b == -1) || (a == -1 && b == 1); }

/// The weights of `corners` (v0, v1, v2 as nine floats) as 2D cross products
/// of the sheared corners, each with the static bound 2^-47 Mx My, where Mx
/// and My bound |a[kx]| + |sx| |a[kz]| and |a[ky]| + |sy| |a[kz]| over the
/// corners a = v - o (docs/exact-leaf-test.md). Miss: two decided signs
/// differ. Hit: all three decided, hence of one sign (a decided sign is never
/// 0). Open: some sign is left to the rules and the exact stage. A triangle
/// with a non-finite corner never comes out as a Hit (its weights or the bound
/// are NaN or infinite, and no comparison decides them), nor does a collinear
/// one (its exact weights sum to 0, so they cannot share a strict sign).
inline Stage double_weights(const ExactRayConst& fr, const std::array<float, 9>& c, StageWeights& out) {
  double x[3], y[3], ax = 0.0, ay = 0.0, az = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double cx = double(c[3 * i + fr.kx]) - fr.ox, cy = double(c[3 * i + fr.ky]) - fr.oy,
                 cz = double(c[3 * i + fr.kz]) - fr.oz;
    x[i] = cx - fr.sx * cz;
    y[i] = cy - fr.sy * cz;
    az = std::max(az, std::abs(cz));
    ax = std::max(ax, std::abs(cx));
    ay = std::max(ay, std::abs(cy));
  }
  const double mx = ax + fr.asx * az, my = ay + fr.asy * az;
  const double bound = 0x1p-47 * (mx * my);
  out.w[0] = x[1] * y[2] - y[1] * x[2];
  out.w[1] = x[2] * y[0] - y[2] * x[0];
  out.s[0] = filtered_sign(out.w[0], bound);
  out.s[1] = filtered_sign(out.w[1], bound);
  if (opposite_signs(out.s[0], out.s[1])) return Stage::Miss;
  out.w[2] = x[0] * y[1] - y[0] * x[1];
  out.s[2] = filtered_sign(out.w[2], bound);
  if (opposite_signs(out.s[0], out.s[2]) || opposite_signs(out.s[1], out.s[2])) return Stage::Miss;
  return (out.s[0] == 2 || out.s[1] == 2 || out.s[2] == 2) ? Stage::Open : Stage::Hit;
}

/// Relative bound of the double t (docs/exact-leaf-test.md, "The double
/// filter"): each of n·A0 and n·d is a sum of at most six monomials of degree
/// three in float inputs, computed with at most 8 roundings of 2^-53 each on
/// any path; 2^-48 leaves a wide margin for that and for the rounded max-abs
/// bound of the monomials.
inline constexpr double kStageRel = 0x1p-48;

/// t = n·(v0 − o) / n·d in double with its static bound, for a line that meets
/// the triangle. Hit: the enclosure [lo, hi] of the exact t lies in
/// [tnear, tfar] and inside one float's rounding interval, so t is the exact t
/// rounded to float. Miss: the enclosure lies outside [tnear, tfar], or t
/// rounds beyond the float range (docs/exact-leaf-test.md, "Hits beyond the
/// float range"). Open: the exact stage must round t.
///
/// One division (docs/exact-leaf-test.md, "The double filter"): with num and
/// den computed within E_n and E_d of the exact N and D, and den > 2 E_d after
/// the sign flip, |N/D − num/den| <= (E_n + |num/den|·E_d)/(den − E_d)
/// <= 2 (E_n + |num/den|·E_d)/den. With r = fl(1/den) and q = fl(num·r),
/// |q − num/den| <= |q|·2^-51, and the bound computed below exceeds the sum of
/// both by the factor 1 + 2^-40, far more than its own few roundings.
inline Stage double_t(const ExactRayConst& fr, const Ray& ray, const std::array<float, 9>& c, float& t, double& lo,
                      double& hi) {
  double f1[3], f2[3], a0[3];
  const double o[3] = {ray.org.x, ray.org.y, ray.org.z};
  for (int k = 0; k < 3; ++k) {
    f1[k] = double(c[3 + k]) - double(c[k]);
    f2[k] = double(c[6 + k]) - double(c[k]);
    a0[k] = double(c[k]) - o[k];
  }
  const double n[3] = {f1[1] * f2[2] - f1[2] * f2[1], f1[2] * f2[0] - f1[0] * f2[2], f1[0] * f2[1] - f1[1] * f2[0]};
  const auto maxabs = [](const double (&v)[3]) { return std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])}); };
  const double mn = 2 * maxabs(f1) * maxabs(f2);
  double num = n[0] * a0[0] + n[1] * a0[1] + n[2] * a0[2];
  double den = n[0] * fr.d[0] + n[1] * fr.d[1] + n[2] * fr.d[2];
  const double enum_ = 3 * kStageRel * (mn * maxabs(a0)), eden = 3 * kStageRel * (mn * maxabs(fr.d));
  if (!(std::abs(den) > 2 * eden)) return Stage::Open;
  if (den < 0) num = -num, den = -den;
  const double r = 1.0 / den, q = num * r, aq = std::abs(q);
  const double b = ((enum_ + aq * eden) * r) * (2 + 0x1p-39) + aq * 0x1p-51;
  double l = q - b, h = q + b;
  l -= std::abs(l) * 0x1p-51;  // the rounding of q ± b
  h += std::abs(h) * 0x1p-51;
  const double tnear = ray.tnear, tfar = ray.tfar;
  if (h < tnear || l > tfar) return Stage::Miss;
  if (!(l >= tnear && h <= tfar)) return Stage::Open;
  const float fl = float(l), fh = float(h);
  if (fl != fh) return Stage::Open;
  if (std::isinf(fl)) return Stage::Miss;  // beyond the float range
  t = fl, lo = l, hi = h;
  return Stage::Hit;
}

/// The reported barycentrics of v1 and v2 from the three weights (any common
/// scale): V/(U+V+W) and W/(U+V+W) in double, rounded to float. Approximations,
/// not decisions (docs/exact-leaf-test.md, "The quantities").
inline void stage_barycentrics(const double (&w)[3], float& u, float& v) {
  const double inv = 1.0 / (w[0] + w[1] + w[2]);
  u = float(w[1] * inv);
  v = float(w[2] * inv);
}

/// The corners of a leaf triangle as nine floats (v0, v1, v2).
inline std::array<float, 9> corner_floats(const LeafTriangle& t) { return std::bit_cast<std::array<float, 9>>(t); }

/// LeafIntersector::intersect(ray, prims[0..count), corners, best, counters),
/// with the double stage inline when the intersector allows it
/// (LeafIntersector::staged()): a triangle whose weights and t the double
/// stage decides, and whose t enclosure is clear of the nearest hit's, is
/// settled here; any other goes to the intersector alone. The intersector
/// decides such a triangle the same way (it runs these functions first) and
/// keeps the nearest by the same comparisons, so the answer, the enclosure
/// and the counters are its own. `ray` must be valid.
/// `fr` = exact_ray_const(ray), made once per ray by the caller.
inline void exact_leaf_staged(const LeafIntersector& x, const Ray& ray, const ExactRayConst& fr,
                              const std::uint32_t* prims, const LeafTriangle* corners, std::uint32_t count,
                              NearestHit& best, RayCounters* c) {
  if (!x.staged() || exact_filter_off_for_testing != 0) {
    x.intersect(ray, std::span<const std::uint32_t>(prims, count), corners, best, c);
    return;
  }
  std::uint64_t tests = 0;
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint32_t prim = prims[i];
    const auto open = [&] { x.intersect(ray, std::span<const std::uint32_t>(prims + i, 1), corners + i, best, c); };
    if (best.hit.hit() && prim == best.hit.prim) {  // met again in another leaf: not nearer than itself
      ++tests;
      continue;
    }
    const std::array<float, 9> tri = corner_floats(corners[i]);
    StageWeights sw;
    const Stage ws = double_weights(fr, tri, sw);
    if (ws == Stage::Miss) {
      ++tests;
      continue;
    }
    if (ws == Stage::Open) {
      open();
      continue;
    }
    float t;
    double lo, hi;
    const Stage ts = double_t(fr, ray, tri, t, lo, hi);
    if (ts == Stage::Miss) {
      ++tests;
      continue;
    }
    if (ts == Stage::Open || (best.hit.hit() && !(hi < best.t_lo) && !(lo > best.t_hi))) {
      open();  // t to round exactly, or enclosures that overlap the nearest hit's
      continue;
    }
    ++tests;
    if (best.hit.hit() && lo > best.t_hi) continue;  // farther
    best.hit = Hit{t, prim, 0.0f, 0.0f};
    stage_barycentrics(sw.w, best.hit.u, best.hit.v);
    best.t_lo = lo;
    best.t_hi = hi;
    best.on = 0;
    best.p = Vec3f{};
    best.q = Vec3f{};
  }
  if (c) c->triangle_tests += tests;
}

/// As above, making the ray's constants for this call.
inline void exact_leaf_staged(const LeafIntersector& x, const Ray& ray, const std::uint32_t* prims,
                              const LeafTriangle* corners, std::uint32_t count, NearestHit& best, RayCounters* c) {
  exact_leaf_staged(x, ray, exact_ray_const(ray), prims, corners, count, best, c);
}

}  // namespace BSPRT_ISA_NAMESPACE
}  // namespace bsprt::detail
