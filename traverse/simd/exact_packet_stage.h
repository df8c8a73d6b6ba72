#pragma once
/// \file exact_packet_stage.h
/// The double stage of the exact leaf test (exact_double_stage.h) for W rays
/// against one triangle, lanes in SIMD registers (GCC vectors of doubles).
/// Lane i computes double_weights() and double_t() of ray i: the same IEEE
/// double operations on the same inputs in the same order (no FMA: the packet
/// translation units are compiled with -ffp-contract=off; std::max and
/// std::abs written as the selects and the sign-bit clear they are), so each
/// lane's weights, signs, t and enclosure are the scalar ones bit for bit, and
/// exact_leaf_staged's decision (staged_decide) runs on them unchanged.
/// Only for packets whose lanes share the shear's axes (kx, ky, kz), which
/// coherent rays do; the others take the scalar stage lane by lane. Include
/// it only from per-ISA kernel translation units.
///
/// Test: "exact packets: bsp and kd equal their single rays and the exact
/// reference at every width" (tests/test_bsp_traverse.cpp), hits compared
/// byte for byte.

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <cstdint>
#include <cstring>
#include <span>

#include "bsprt/ray.h"
#include "traverse/exact_double_stage.h"
#include "traverse/leaf_intersector.h"
#include "traverse/simd/simd.h"

namespace bsprt::simd {
inline namespace BSPRT_ISA_NAMESPACE {

namespace exact_stage_detail {
template <int W>
inline vdouble<W> dabs(vdouble<W> x) {  // std::abs: the sign bit cleared (NaN and -0 included)
  return reinterpret_cast<vdouble<W>>(reinterpret_cast<vmask64<W>>(x) & ~(vmask64<W>{} + INT64_MIN));
}
template <int W>
inline vdouble<W> dmax(vdouble<W> a, vdouble<W> b) {  // std::max(a, b) = (a < b) ? b : a
  return a < b ? b : a;
}
template <int W>
inline vmask64<W> filtered_sign(vdouble<W> x, vdouble<W> bound) {  // detail::filtered_sign
  const vmask64<W> one = vmask64<W>{} + 1, minus = vmask64<W>{} - 1, two = vmask64<W>{} + 2;
  return x > bound ? one : (x < -bound ? minus : two);
}
template <int W>
inline vmask64<W> opposite(vmask64<W> a, vmask64<W> b) {  // detail::opposite_signs
  return ((a == 1) & (b == -1)) | ((a == -1) & (b == 1));
}
}  // namespace exact_stage_detail

/// The lanes' ExactRayConst in SoA form, for a packet whose live lanes share
/// (kx, ky, kz), made by packet_exact_rays. Lanes that are not live hold zeros
/// and 1 as d[kz] (never read).
template <int W>
struct PacketExactRays {
  alignas(64) double ox[W], oy[W], oz[W], sx[W], sy[W], asx[W], asy[W];
  alignas(64) double d[3][W], o[3][W], tnear[W], tfar[W];
  int kx = 0, ky = 1, kz = 2;
  bool uniform = false;  ///< the live lanes share the axes: the vector stage applies
};

/// The constants of the lanes in `lanes`, as exact_ray_const makes them: the
/// axes lane by lane (no arithmetic), then, when the lanes share them, the
/// shear's two divisions four lanes at a time (the same IEEE divisions).
template <int W>
inline void packet_exact_rays(const Ray* rays, unsigned lanes, PacketExactRays<W>& p) {
  // Not p = PacketExactRays<W>{}: clearing all of it cost 250 instructions a
  // call (31 a ray on sponza camera packets of 8); every field read is written below.
  p.kx = 0, p.ky = 1, p.kz = 2;
  p.uniform = true;
  bool first = true;
  for (unsigned m = lanes; m != 0; m &= m - 1) {
    const int i = __builtin_ctz(m);
    const Ray& ray = rays[i];
    const double d[3] = {ray.dir.x, ray.dir.y, ray.dir.z};
    int kx, ky, kz;
    detail::exact_axes(d[0], d[1], d[2], kx, ky, kz);  // exact_ray_const's choice
    if (first) {
      p.kx = kx, p.ky = ky, p.kz = kz, first = false;
    } else if (kx != p.kx || ky != p.ky || kz != p.kz) {
      p.uniform = false;
      return;
    }
    for (int k = 0; k < 3; ++k) p.d[k][i] = d[k], p.o[k][i] = ray.org[k];
    p.tnear[i] = ray.tnear, p.tfar[i] = ray.tfar;
  }
  for (int i = 0; i < W; ++i)
    if (((lanes >> i) & 1u) == 0) {  // an unused lane: zeros, and no division by zero
      for (int k = 0; k < 3; ++k) p.d[k][i] = 0.0, p.o[k][i] = 0.0;
      p.d[p.kz][i] = 1.0;
      p.tnear[i] = 0.0, p.tfar[i] = 0.0;
    }
  for (int i = 0; i < W; ++i) p.ox[i] = p.o[p.kx][i], p.oy[i] = p.o[p.ky][i], p.oz[i] = p.o[p.kz][i];
  using V = vdouble<4>;
  for (int j = 0; j < W; j += 4) {
    V dx, dy, dz;
    std::memcpy(&dx, p.d[p.kx] + j, sizeof(V));
    std::memcpy(&dy, p.d[p.ky] + j, sizeof(V));
    std::memcpy(&dz, p.d[p.kz] + j, sizeof(V));
    const V sx = dx / dz, sy = dy / dz;
    const V asx = exact_stage_detail::dabs<4>(sx), asy = exact_stage_detail::dabs<4>(sy);
    std::memcpy(p.sx + j, &sx, sizeof(V));
    std::memcpy(p.sy + j, &sy, sizeof(V));
    std::memcpy(p.asx + j, &asx, sizeof(V));
    std::memcpy(p.asy + j, &asy, sizeof(V));
  }
}

/// Per lane: the double stage's weights and signs (StageWeights), its verdict
/// on them, and double_t's verdict, t and enclosure.
template <int W>
struct PacketStageOut {
  alignas(64) double w[3][W];
  alignas(64) std::int64_t s[3][W];
  alignas(64) std::int64_t ws[W];  ///< detail::Stage of double_weights
  alignas(64) std::int64_t ts[W];  ///< detail::Stage of double_t
  alignas(64) double lo[W], hi[W];
  alignas(64) float t[W];
};


/// Lanes per chunk of the vector stage: the ISA's own vector of doubles, four
/// on AVX2, eight on AVX-512 (wider GCC vectors of doubles than the ISA's
/// compiled to ten times the instructions). Packets narrower than a chunk
/// take one chunk of their width.
#if defined(__AVX512F__)
inline constexpr int kStageChunk = 8;
#else
inline constexpr int kStageChunk = 4;
#endif

/// double_weights and double_t of the lanes in `need` against triangle `c`
/// (nine floats, v0 v1 v2), into `out`, kStageChunk lanes at a time (chunks with no
/// lane in `need` are skipped; their entries are not written). `r` must be uniform.
template <int W>
inline void packet_double_stage(const PacketExactRays<W>& r, const std::array<float, 9>& c, unsigned need,
                                PacketStageOut<W>& out) {
  using namespace exact_stage_detail;
  constexpr int C = W < kStageChunk ? W : kStageChunk;
  using V = vdouble<C>;
  using M = vmask64<C>;
  using F = vfloat<C>;
  using I = vint<C>;
  const auto ld = [](const double* p) {
    V v;
    std::memcpy(&v, p, sizeof(v));
    return v;
  };
  const auto put = [](auto* dst, const auto& v) { std::memcpy(dst, &v, sizeof(v)); };
  // The triangle's part of double_t: its face normal and the normal's bound.
  double f1[3], f2[3];
  for (int k = 0; k < 3; ++k) {
    f1[k] = double(c[3 + k]) - double(c[k]);
    f2[k] = double(c[6 + k]) - double(c[k]);
  }
  const double n[3] = {f1[1] * f2[2] - f1[2] * f2[1], f1[2] * f2[0] - f1[0] * f2[2], f1[0] * f2[1] - f1[1] * f2[0]};
  const auto maxabs3 = [](const double (&v)[3]) { return std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])}); };
  const double mn = 2 * maxabs3(f1) * maxabs3(f2);
  const auto vmaxabs3 = [](const V (&v)[3]) {  // std::max({...}): the first largest
    V m = dabs<C>(v[0]);
    const V b = dabs<C>(v[1]), e = dabs<C>(v[2]);
    m = m < b ? b : m;
    return m < e ? e : m;
  };
  const M kMiss = M{} + std::int64_t(detail::Stage::Miss), kHit = M{} + std::int64_t(detail::Stage::Hit),
          kOpen = M{} + std::int64_t(detail::Stage::Open);
  for (int j = 0; j < W; j += C) {
    if (((need >> j) & ((1u << C) - 1u)) == 0) continue;
    // double_weights
    const V ox = ld(r.ox + j), oy = ld(r.oy + j), oz = ld(r.oz + j), sx = ld(r.sx + j), sy = ld(r.sy + j);
    V x[3], y[3], ax = V{}, ay = V{}, az = V{};
    for (int i = 0; i < 3; ++i) {
      const V cx = double(c[3 * i + r.kx]) - ox, cy = double(c[3 * i + r.ky]) - oy, cz = double(c[3 * i + r.kz]) - oz;
      x[i] = cx - sx * cz;
      y[i] = cy - sy * cz;
      az = dmax<C>(az, dabs<C>(cz));
      ax = dmax<C>(ax, dabs<C>(cx));
      ay = dmax<C>(ay, dabs<C>(cy));
    }
    const V mx = ax + ld(r.asx + j) * az, my = ay + ld(r.asy + j) * az;
    const V bound = 0x1p-47 * (mx * my);
    const V w0 = x[1] * y[2] - y[1] * x[2], w1 = x[2] * y[0] - y[2] * x[0], w2 = x[0] * y[1] - y[0] * x[1];
    const M s0 = filtered_sign<C>(w0, bound), s1 = filtered_sign<C>(w1, bound), s2 = filtered_sign<C>(w2, bound);
    const M miss = opposite<C>(s0, s1) | opposite<C>(s0, s2) | opposite<C>(s1, s2);
    const M open = (s0 == 2) | (s1 == 2) | (s2 == 2);
    const M ws = miss ? kMiss : (open ? kOpen : kHit);
    // double_t
    const V d[3] = {ld(r.d[0] + j), ld(r.d[1] + j), ld(r.d[2] + j)};
    V a0[3];
    for (int k = 0; k < 3; ++k) a0[k] = double(c[k]) - ld(r.o[k] + j);
    V num = n[0] * a0[0] + n[1] * a0[1] + n[2] * a0[2];
    V den = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    const V enum_ = 3 * detail::kStageRel * (mn * vmaxabs3(a0)), eden = 3 * detail::kStageRel * (mn * vmaxabs3(d));
    const M open1 = ~(dabs<C>(den) > 2 * eden);
    const M flip = den < 0;
    num = flip ? -num : num;
    den = flip ? -den : den;
    const V rcp = 1.0 / den, q = num * rcp, aq = dabs<C>(q);
    const V b = ((enum_ + aq * eden) * rcp) * (2 + 0x1p-39) + aq * 0x1p-51;
    V l = q - b, h = q + b;
    l -= dabs<C>(l) * 0x1p-51;
    h += dabs<C>(h) * 0x1p-51;
    const V tnear = ld(r.tnear + j), tfar = ld(r.tfar + j);
    const M miss1 = (h < tnear) | (l > tfar);
    const M open2 = ~((l >= tnear) & (h <= tfar));
    const F fl = __builtin_convertvector(l, F), fh = __builtin_convertvector(h, F);
    const M open3 = __builtin_convertvector(I(fl != fh), M);
    const F inf = F{} + __builtin_inff();
    const M infl = __builtin_convertvector(I((fl == inf) | (fl == -inf)), M);
    const M ts = open1 ? kOpen : (miss1 ? kMiss : (open2 ? kOpen : (open3 ? kOpen : (infl ? kMiss : kHit))));
    put(out.w[0] + j, w0), put(out.w[1] + j, w1), put(out.w[2] + j, w2);
    put(out.s[0] + j, s0), put(out.s[1] + j, s1), put(out.s[2] + j, s2);
    put(out.ws + j, ws), put(out.ts + j, ts), put(out.lo + j, l), put(out.hi + j, h), put(out.t + j, fl);
  }
}

/// The staged decision (detail::staged_decide) of lane `i` on `out`, for the
/// triangle `prim` with corners `tri`; open() as in exact_leaf_staged.
template <int W, class Fr, class Open>
inline void packet_staged_lane(const PacketStageOut<W>& out, int i, Fr&& fr, const Ray& ray, std::uint32_t prim,
                               const std::array<float, 9>& tri, Open&& open, NearestHit& best) {
  detail::StageWeights sw;
  for (int k = 0; k < 3; ++k) sw.w[k] = out.w[k][i], sw.s[k] = int(out.s[k][i]);
  const auto tstage = [&](float& t, double& lo, double& hi) {
    t = out.t[i], lo = out.lo[i], hi = out.hi[i];
    return detail::Stage(out.ts[i]);
  };
  std::uint64_t tests = 0, rules = 0;  // packets are never counted
  detail::staged_decide(fr, ray, prim, tri, detail::Stage(out.ws[i]), sw, tstage, open, best, tests, rules);
}

/// The exact leaf test of one triangle (number *prim, corners t) for the lanes
/// in `need`, each lane's nearest hit updated as exact_leaf_staged updates it:
/// with the vector double stage when the packet is uniform and more than one
/// lane needs it, else lane by lane. Returns the lanes whose cull bound may
/// have changed (cull_bound reads only t_hi, which every new hit sets). Never
/// counted (packets are not).
template <int W>
inline unsigned packet_exact_triangle(const LeafIntersector& x, const PacketExactRays<W>& pr, const Ray* rays,
                                      detail::LazyExactRay* er, NearestHit* nearest, unsigned need,
                                      const std::uint32_t* prim, const LeafTriangle& t) {
  if (need == 0) return 0;
  unsigned changed = 0;
  const bool vec = pr.uniform && (need & (need - 1)) != 0 && x.staged() && exact_filter_off_for_testing == 0;
  if (!vec) {
    for (unsigned m = need; m != 0; m &= m - 1) {
      const int lane = __builtin_ctz(m);
      const double before = nearest[lane].t_hi;
      detail::exact_leaf_staged(x, rays[lane], er[lane].get(rays[lane]), prim, &t, 1, nearest[lane], nullptr);
      if (!(nearest[lane].t_hi == before)) changed |= 1u << lane;
    }
    return changed;
  }
  const std::array<float, 9> tri = detail::corner_floats(t);
  PacketStageOut<W> out;
  packet_double_stage<W>(pr, tri, need, out);
  for (unsigned m = need; m != 0; m &= m - 1) {
    const int lane = __builtin_ctz(m);
    NearestHit& best = nearest[lane];
    if (best.hit.hit() && *prim == best.hit.prim) continue;  // met again in another leaf
    const double before = best.t_hi;
    const auto open = [&] { x.intersect(rays[lane], std::span<const std::uint32_t>(prim, 1), &t, best, nullptr); };
    const auto fr = [&]() -> const detail::ExactRayConst& { return er[lane].get(rays[lane]); };
    if (best.on == 1 && detail::vertex_tie(fr(), *prim, tri, best)) continue;
    packet_staged_lane<W>(out, lane, fr, rays[lane], *prim, tri, open, best);
    if (!(best.t_hi == before)) changed |= 1u << lane;
  }
  return changed;
}

}  // namespace BSPRT_ISA_NAMESPACE
}  // namespace bsprt::simd
