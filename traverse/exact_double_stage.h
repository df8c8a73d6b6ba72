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
/// (tests/test_exact_leaf.cpp).

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

/// Component k of (a, b, c), by selects.
inline double pick_axis(int k, double a, double b, double c) { return k == 0 ? a : (k == 1 ? b : c); }

/// The shear's axes of direction (dx, dy, dz): kz of the largest |d|, (kx, ky,
/// kz) cyclic, or swapped when d[kz] < 0 (ExactRayConst).
inline void exact_axes(double dx, double dy, double dz, int& kx, int& ky, int& kz) {
  const double ax = std::abs(dx), ay = std::abs(dy), az = std::abs(dz);
  kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
  kx = kz == 2 ? 0 : kz + 1;
  ky = kx == 2 ? 0 : kx + 1;
  if (pick_axis(kz, dx, dy, dz) < 0) std::swap(kx, ky);
}

/// exact_ray_const(ray), written into `f` in place. The axes pick their
/// components by selects, not by indexing arrays: an array indexed at run time
/// lives on the stack, and GCC then copied the finished struct with loads wider
/// than the stores that made it, which cannot be forwarded (perf: the hottest
/// instructions of `bsp`'s per-ray setup on sponza camera rays).
inline void exact_ray_init(const Ray& ray, ExactRayConst& f) {
  const double dx = ray.dir.x, dy = ray.dir.y, dz = ray.dir.z;
  f.d[0] = dx, f.d[1] = dy, f.d[2] = dz;
  int kx, ky, kz;
  exact_axes(dx, dy, dz, kx, ky, kz);
  const double dk = pick_axis(kz, dx, dy, dz);
  f.kx = kx, f.ky = ky, f.kz = kz;
  const double ox = ray.org.x, oy = ray.org.y, oz = ray.org.z;
  f.ox = pick_axis(kx, ox, oy, oz), f.oy = pick_axis(ky, ox, oy, oz), f.oz = pick_axis(kz, ox, oy, oz);
  f.abs_d = std::abs(dk);
  f.sx = pick_axis(kx, dx, dy, dz) / dk;
  f.sy = pick_axis(ky, dx, dy, dz) / dk;
  f.asx = std::abs(f.sx);
  f.asy = std::abs(f.sy);
}

inline ExactRayConst exact_ray_const(const Ray& ray) {
  ExactRayConst f;
  exact_ray_init(ray, f);
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
/// double_t_range is the part before the rounding: its Hit says only that
/// the exact t lies in [tnear, tfar] (enclosed by [l, h]).
///
/// One division (docs/exact-leaf-test.md, "The double filter"): with num and
/// den computed within E_n and E_d of the exact N and D, and den > 2 E_d after
/// the sign flip, |N/D − num/den| <= (E_n + |num/den|·E_d)/(den − E_d)
/// <= 2 (E_n + |num/den|·E_d)/den. With r = fl(1/den) and q = fl(num·r),
/// |q − num/den| <= |q|·2^-51, and the bound computed below exceeds the sum of
/// both by the factor 1 + 2^-40, far more than its own few roundings.
inline double maxabs3(const double (&v)[3]) { return std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])}); }

/// The face normal n = (v1 - v0) x (v2 - v0) in double, the scale mn of its
/// error, and den = n·d with its bound eden (double_t's D and E_d): |den| >
/// 2 eden proves that the exact n·d is not 0, i.e. that the ray crosses the
/// triangle's plane.
inline double double_den(const ExactRayConst& fr, const std::array<float, 9>& c, double (&n)[3], double& mn,
                         double& eden) {
  double f1[3], f2[3];
  for (int k = 0; k < 3; ++k) {
    f1[k] = double(c[3 + k]) - double(c[k]);
    f2[k] = double(c[6 + k]) - double(c[k]);
  }
  n[0] = f1[1] * f2[2] - f1[2] * f2[1], n[1] = f1[2] * f2[0] - f1[0] * f2[2], n[2] = f1[0] * f2[1] - f1[1] * f2[0];
  mn = 2 * maxabs3(f1) * maxabs3(f2);
  eden = 3 * kStageRel * (mn * maxabs3(fr.d));
  return n[0] * fr.d[0] + n[1] * fr.d[1] + n[2] * fr.d[2];
}

inline Stage double_t_range(const ExactRayConst& fr, const Ray& ray, const std::array<float, 9>& c, double& l,
                            double& h) {
  double n[3], mn, eden;
  double den = double_den(fr, c, n, mn, eden);
  const double a0[3] = {double(c[0]) - double(ray.org.x), double(c[1]) - double(ray.org.y),
                        double(c[2]) - double(ray.org.z)};
  double num = n[0] * a0[0] + n[1] * a0[1] + n[2] * a0[2];
  const double enum_ = 3 * kStageRel * (mn * maxabs3(a0));
  if (!(std::abs(den) > 2 * eden)) return Stage::Open;
  if (den < 0) num = -num, den = -den;
  const double r = 1.0 / den, q = num * r, aq = std::abs(q);
  const double b = ((enum_ + aq * eden) * r) * (2 + 0x1p-39) + aq * 0x1p-51;
  l = q - b, h = q + b;
  l -= std::abs(l) * 0x1p-51;  // the rounding of q ± b
  h += std::abs(h) * 0x1p-51;
  const double tnear = ray.tnear, tfar = ray.tfar;
  if (h < tnear || l > tfar) return Stage::Miss;
  if (!(l >= tnear && h <= tfar)) return Stage::Open;
  return Stage::Hit;
}

inline Stage double_t(const ExactRayConst& fr, const Ray& ray, const std::array<float, 9>& c, float& t, double& lo,
                      double& hi) {
  double l, h;
  const Stage range = double_t_range(fr, ray, c, l, h);
  if (range != Stage::Hit) return range;
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

/// Whether a - b (floats) is exact in double: Knuth's two-sum error is zero.
inline bool exact_difference(float a, float b) {
  const double x = a, y = -double(b), s = x + y, yv = s - x, xv = s - yv;
  return (x - xv) + (y - yv) == 0.0;
}

/// Rule (a) on exact zeros (docs/exact-leaf-test.md, "Rules on exact zeros"):
/// a corner v_i with v_i - o == ±d exactly (each difference exact in double)
/// makes the two weights that pair it with d exactly 0; those of them still
/// open (s == 2) become 0. True when the rule set any. Only a corner whose two
/// weights are both open can qualify: a decided sign is never an exact 0.
inline bool vertex_rule(const ExactRayConst& fr, const Ray& ray, const std::array<float, 9>& c, StageWeights& sw) {
  const float o[3] = {ray.org.x, ray.org.y, ray.org.z};
  const bool open[3] = {sw.s[0] == 2, sw.s[1] == 2, sw.s[2] == 2};
  bool rule = false;
  for (int i = 0; i < 3; ++i) {
    if (!open[i == 0 ? 1 : 0] || !open[i == 2 ? 1 : 2]) continue;
    const double a[3] = {double(c[3 * i]) - double(o[0]), double(c[3 * i + 1]) - double(o[1]),
                         double(c[3 * i + 2]) - double(o[2])};
    const bool same = a[0] == fr.d[0] && a[1] == fr.d[1] && a[2] == fr.d[2];
    const bool opposite = a[0] == -fr.d[0] && a[1] == -fr.d[1] && a[2] == -fr.d[2];
    if (!(same || opposite)) continue;
    if (!exact_difference(c[3 * i], o[0]) || !exact_difference(c[3 * i + 1], o[1]) ||
        !exact_difference(c[3 * i + 2], o[2]))
      continue;
    for (int k = 0; k < 3; ++k)
      if (k != i && sw.s[k] == 2) sw.s[k] = 0, sw.w[k] = 0.0, rule = true;
  }
  return rule;
}

/// One sign for all three weights, not all zero: the line meets the triangle.
inline bool meets(const int (&s)[3]) {
  const bool neg = s[0] < 0 || s[1] < 0 || s[2] < 0, pos = s[0] > 0 || s[1] > 0 || s[2] > 0;
  return !(neg && pos) && (neg || pos);
}

/// Where a hit with decided signs `s` lies on its triangle (NearestHit::on,
/// p, q): at the corner whose weight is the only non-zero one, on the edge
/// opposite the corner whose weight is the only zero one, else inside.
inline void hit_place(const int (&s)[3], const std::array<float, 9>& c, std::uint8_t& on, Vec3f& p, Vec3f& q) {
  const auto corner = [&](int i) { return Vec3f{c[3 * i], c[3 * i + 1], c[3 * i + 2]}; };
  const int zeros = int(s[0] == 0) + int(s[1] == 0) + int(s[2] == 0);
  on = 0, p = Vec3f{}, q = Vec3f{};
  if (zeros == 2) {
    on = 1;
    p = corner(s[0] != 0 ? 0 : (s[1] != 0 ? 1 : 2));
  } else if (zeros == 1) {
    const int k = s[0] == 0 ? 0 : (s[1] == 0 ? 1 : 2);  // the edge opposite corner k
    on = 2;
    p = corner((k + 1) % 3);
    q = corner((k + 2) % 3);
  }
}

inline bool same_point(const Vec3f& a, const Vec3f& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

/// Rule (b) on exact zeros for two hits placed on a corner or an edge: the
/// same corner, or the same edge in either order, means the same exact t.
inline bool same_place(std::uint8_t on, const Vec3f& p, const Vec3f& q, const NearestHit& best) {
  if (on == 1 && best.on == 1) return same_point(p, best.p);
  if (on == 2 && best.on == 2)
    return (same_point(p, best.p) && same_point(q, best.q)) || (same_point(p, best.q) && same_point(q, best.p));
  return false;
}

/// Whether two triangles (nine floats each) have the same three corners, in
/// any order: coplanar duplicates (a copy with reversed winding), whose hits
/// have the same exact t for any ray.
inline bool same_corners(const std::array<float, 9>& a, const std::array<float, 9>& b) {
  const auto in = [](const std::array<float, 9>& x, int i, const std::array<float, 9>& y) {
    for (int j = 0; j < 3; ++j)
      if (x[3 * i] == y[3 * j] && x[3 * i + 1] == y[3 * j + 1] && x[3 * i + 2] == y[3 * j + 2]) return true;
    return false;
  };
  for (int i = 0; i < 3; ++i)
    if (!in(a, i, b) || !in(b, i, a)) return false;
  return true;
}

/// The points a hit is known to lie among, by its place (NearestHit::on):
/// its vertex, the two ends of its edge, or its triangle's three corners.
/// The hit lies in their convex hull, so in any plane that holds them all.
inline int known_points(std::uint8_t on, const Vec3f& p, const Vec3f& q, const std::array<float, 9>& tri,
                        Vec3f (&out)[3]) {
  if (on == 1) return out[0] = p, 1;
  if (on == 2) return out[0] = p, out[1] = q, 2;
  for (int i = 0; i < 3; ++i) out[i] = Vec3f{tri[3 * i], tri[3 * i + 1], tri[3 * i + 2]};
  return 3;
}

/// Whether two hits have the same exact t by the rules that need only float
/// comparisons (docs/exact-leaf-test.md, "Rules on exact zeros"): the same
/// vertex or edge (rule (b), same_place), triangles with the same corners, or
/// hits whose known points (the vertex, the edge's ends, else the triangle's
/// corners) all lie in one axis plane x_k = c that the ray crosses
/// (d[k] != 0). The exact-decision intersector's same_t_by_rule calls it
/// first, so a tie settled here is settled there the same way and counted
/// as the same rule decision.
inline bool same_t_by_corners(std::uint8_t on, const Vec3f& p, const Vec3f& q, const std::array<float, 9>& tri,
                              const NearestHit& best, const Ray& ray) {
  if (on != 0 && on == best.on && same_place(on, p, q, best)) return true;
  if (same_corners(tri, best.tri)) return true;
  Vec3f a3[3], b3[3];
  const int na = known_points(on, p, q, tri, a3), nb = known_points(best.on, best.p, best.q, best.tri, b3);
  for (int k = 0; k < 3; ++k) {
    if (ray.dir[k] == 0.0f) continue;
    const float c = a3[0][k];
    bool same = true;
    for (int i = 1; i < na && same; ++i) same = a3[i][k] == c;
    for (int i = 0; i < nb && same; ++i) same = b3[i][k] == c;
    if (same) return true;
  }
  return false;
}

/// Rule (b) at a vertex, before any stage (docs/exact-leaf-test.md, "Rules
/// on exact zeros"): when the nearest hit so far lies at a vertex (best.on ==
/// 1, so the ray passes exactly through best.p), a triangle with a corner at
/// that vertex whose plane the ray crosses (double_den's bound) meets the ray
/// there and nowhere else: its exact t is the nearest hit's, and the tie goes
/// to the smaller triangle number. Returns whether it settled the triangle; a
/// new nearest keeps the same t, enclosure and vertex, with the barycentrics
/// of its corner (those the stages would give it: weights 0 but one). Both the
/// traversals' staged test and the exact-decision intersector run it first,
/// so they keep agreeing field for field and counter for counter. Rays
/// through a vertex meet every triangle around it, each otherwise a full
/// double stage and rule (a).
inline bool vertex_tie(const ExactRayConst& fr, std::uint32_t prim, const std::array<float, 9>& c, NearestHit& best) {
  if (best.on != 1) return false;
  int corner = -1;
  for (int i = 0; i < 3; ++i)
    if (c[3 * i] == best.p.x && c[3 * i + 1] == best.p.y && c[3 * i + 2] == best.p.z) corner = i;
  if (corner < 0) return false;
  double n[3], mn, eden;
  const double den = double_den(fr, c, n, mn, eden);
  if (!(std::abs(den) > 2 * eden)) return false;
  if (prim < best.hit.prim) {
    // The weights sum to n·d / |d[kz]| (the shear keeps triple products), so
    // the one non-zero weight has den's sign, and the stages' u and v are
    // w1/w and w2/w with the rule's +0 for the zero ones: 1, or a zero of
    // den's sign.
    const float zero = den < 0 ? -0.0f : 0.0f;
    best.hit.prim = prim;
    best.hit.u = corner == 1 ? 1.0f : zero;
    best.hit.v = corner == 2 ? 1.0f : zero;
    best.tri = c;
  }
  return true;
}

/// The corners of a leaf triangle as nine floats (v0, v1, v2).
inline std::array<float, 9> corner_floats(const LeafTriangle& t) { return std::bit_cast<std::array<float, 9>>(t); }

/// The staged test's decision for one triangle whose weights the double
/// stage has computed (`ws`, `sw`, from double_weights), in
/// exact_leaf_staged's order: rule (a) for open signs, then t from
/// `tstage(t, lo, hi)` (double_t's result, computed on demand or given by a
/// packet kernel, bit for bit the same), then the nearest hit with rule (b).
/// Anything the double stage and the rules leave open goes to `open()`
/// before anything about the triangle is counted. The caller has checked
/// that prim is not the nearest hit already. `fr()` gives the ray's
/// ExactRayConst (rule (a) needs it; a packet kernel makes it on demand).
template <bool kAnyHit = false, class Fr, class TStage, class Open>
[[gnu::always_inline]] inline void staged_decide(Fr&& fr, const Ray& ray, std::uint32_t prim,
                                                 const std::array<float, 9>& tri, Stage ws, StageWeights& sw,
                                                 TStage&& tstage, Open&& open, NearestHit& best,
                                                 std::uint64_t& tests, std::uint64_t& rules) {
  if (ws == Stage::Miss) {
    ++tests;
    return;
  }
  std::uint64_t rule = 0;  // rule (a) decided a sign of this triangle
  if (ws == Stage::Open) {
    if (!vertex_rule(fr(), ray, tri, sw) || sw.s[0] == 2 || sw.s[1] == 2 || sw.s[2] == 2) {
      open();  // a sign for the exact stage
      return;
    }
    rule = 1;
    if (!meets(sw.s)) {
      ++tests, ++rules;
      return;
    }
  }
  float t = 0.0f;  // set by tstage when it returns Hit; zeros keep gcc's LTO from warning
  double lo = 0.0, hi = 0.0;
  Stage ts = tstage(t, lo, hi);
  // Any hit (occluded): a t certainly in [tnear, tfar] will do, rounded or
  // not; only a hit whose enclosure reaches past the float range, at either
  // end, stays open (a negative t below -FLT_MAX is as much a miss as a
  // positive one above it: found by a review of 2026-12-07, with tnear = -inf).
  if constexpr (kAnyHit)
    if (ts == Stage::Open && double_t_range(fr(), ray, tri, lo, hi) == Stage::Hit && std::isfinite(float(lo)) &&
        std::isfinite(float(hi)))
      ts = Stage::Hit, t = float(hi);
  if (ts == Stage::Miss) {
    ++tests, rules += rule;
    return;
  }
  if (ts == Stage::Open) {
    open();  // t to round exactly
    return;
  }
  std::uint8_t on = 0;  // inside unless rule (a) put a zero in the signs
  Vec3f p{}, q{};
  if (rule) hit_place(sw.s, tri, on, p, q);
  bool nearer;
  if (!best.hit.hit() || hi < best.t_lo) {
    nearer = true;
  } else if (lo > best.t_hi) {
    nearer = false;
  } else if (same_t_by_corners(on, p, q, tri, best, ray)) {  // rule (b) and its kin: the same exact t
    ++rule;
    nearer = prim < best.hit.prim;
  } else {
    open();  // enclosures that overlap: the intersector compares them
    return;
  }
  ++tests, rules += rule;
  if (!nearer) return;
  best.hit = Hit{t + 0.0f, prim, 0.0f, 0.0f};  // a zero t is +0 in every exact mode, as the exact reference reports it
  stage_barycentrics(sw.w, best.hit.u, best.hit.v);
  best.t_lo = lo;
  best.t_hi = hi;
  best.on = on;
  best.p = p;
  best.q = q;
  best.tri = tri;
}

/// One triangle of exact_leaf_staged, its corners given as nine floats
/// (`tri`; a traversal may gather them from its own rows): the same decision,
/// with the same counts added to `tests` and `rules`. Whatever the stages
/// leave open goes to the intersector with the corners written out. The
/// caller checks what exact_leaf_staged checks first: x.staged(), and the
/// test hook exact_filter_off_for_testing off.
template <bool kAnyHit = false>
[[gnu::always_inline]] inline void exact_one_staged(const LeafIntersector& x, const Ray& ray, const ExactRayConst& fr,
                                                    std::uint32_t prim, const std::array<float, 9>& tri,
                                                    NearestHit& best, RayCounters* c, std::uint64_t& tests,
                                                    std::uint64_t& rules) {
  const auto open = [&] {
    const LeafTriangle corners = std::bit_cast<LeafTriangle>(tri);
    x.intersect(ray, std::span<const std::uint32_t>(&prim, 1), &corners, best, c);
  };
  if (best.hit.hit() && prim == best.hit.prim) {  // met again in another leaf: not nearer than itself
    ++tests;
    return;
  }
  if (vertex_tie(fr, prim, tri, best)) {
    ++tests, ++rules;
    return;
  }
  StageWeights sw;
  const Stage ws = double_weights(fr, tri, sw);
  const auto tstage = [&](float& t, double& lo, double& hi) { return double_t(fr, ray, tri, t, lo, hi); };
  staged_decide<kAnyHit>([&]() -> const ExactRayConst& { return fr; }, ray, prim, tri, ws, sw, tstage, open, best,
                         tests, rules);
}

/// LeafIntersector::intersect(ray, prims[0..count), corners, best, counters),
/// with the double stage and the rules on exact zeros inline when the
/// intersector allows it (LeafIntersector::staged()). A triangle is settled
/// here when the double stage, with rule (a) for what it leaves open, decides
/// its weights and its t, and its t enclosure is clear of the nearest hit's
/// or ties with it at the same corner or edge (rule (b)). Any other triangle
/// (a sign or a t for the exact stage, an overlap only the intersector can
/// settle) goes to the intersector alone, before anything about it is
/// counted. The intersector decides a settled triangle the same way (it runs
/// these functions first, in the same order) and keeps the nearest by the
/// same comparisons, so the answer, the enclosure and the counters are its
/// own. `ray` must be valid. `fr` = exact_ray_const(ray), made once per ray by
/// the caller. kAnyHit (occluded): a hit certainly in [tnear, tfar] is taken
/// without rounding its t (staged_decide), so `best` then holds some hit, not
/// necessarily with the nearest float t; only whether there is one counts.
template <bool kAnyHit = false>
[[gnu::always_inline]] inline void exact_leaf_staged(const LeafIntersector& x, const Ray& ray, const ExactRayConst& fr,
                                                     const std::uint32_t* prims, const LeafTriangle* corners,
                                                     std::uint32_t count, NearestHit& best, RayCounters* c) {
  if (!x.staged() || exact_filter_off_for_testing != 0) {
    x.intersect(ray, std::span<const std::uint32_t>(prims, count), corners, best, c);
    return;
  }
  std::uint64_t tests = 0, rules = 0;
  for (std::uint32_t i = 0; i < count; ++i)
    exact_one_staged<kAnyHit>(x, ray, fr, prims[i], corner_floats(corners[i]), best, c, tests, rules);
  if (c) c->triangle_tests += tests, c->rule_decisions += rules;
}

/// The ray's double constants, made on first use (exact_ray_const costs two
/// divisions): a traversal keeps one per ray and passes it to every leaf, so
/// a ray whose leaves the float prefilter empties never pays for them.
struct LazyExactRay {
  ExactRayConst fr;
  bool ready = false;
  const ExactRayConst& get(const Ray& ray) {
    if (!ready) exact_ray_init(ray, fr), ready = true;
    return fr;
  }
};

}  // namespace BSPRT_ISA_NAMESPACE
}  // namespace bsprt::detail
