#pragma once
/// \file watertight_packet.h
/// Packet form of the watertight test (watertight.h): W rays against one
/// triangle, lanes in SIMD registers. Include it only from per-ISA kernel
/// translation units (compiled with -msse4.2 / -mavx2 / -mavx512f); everything
/// lives in the ISA inline namespace of simd.h.
///
/// Bit-identical to the scalar test: the per-ray constants are made by the
/// scalar watertight_precompute, each lane then runs the same IEEE operations in
/// the same order (no FMA), lanes whose float edge function is exactly 0 take
/// the same double fallback, and ties keep the earlier triangle.
///
/// Rays in a packet may have different dominant axes; the permutation is done
/// with per-lane selects, or directly when all lanes share it (coherent rays).

#include <cstdint>
#include <limits>
#include <span>

#include "bsprt/ray.h"
#include "traverse/simd/simd.h"
#include "traverse/watertight.h"

namespace bsprt::simd {
inline namespace BSPRT_ISA_NAMESPACE {

/// W rays in SoA form, as a packet traversal carries them.
template <int W>
struct RayPacket {
  vfloat<W> org[3];  ///< origin x, y, z
  vfloat<W> dir[3];  ///< direction x, y, z
  vfloat<W> tnear;   ///< segment start
  vfloat<W> tfar;    ///< segment end
};

/// Per-lane constants of the watertight test (WatertightRay in SoA form).
template <int W>
struct WatertightPacket {
  vfloat<W> org[3];         ///< ray origins
  vfloat<W> sx, sy, sz;     ///< shear and scale
  vfloat<W> tnear, tfar;    ///< segments
  vmask<W> kx0, kx1;        ///< kx == 0, kx == 1 (else 2), per lane
  vmask<W> ky0, ky1;        ///< ky == 0, ky == 1
  vmask<W> kz0, kz1;        ///< kz == 0, kz == 1
  vmask<W> valid;           ///< lane holds a valid ray (padding lanes are false)
  bool uniform = false;     ///< all valid lanes share (kx, ky, kz) below
  int kx = 0, ky = 1, kz = 2;
};

/// Nearest hits of W rays; prim is kNoHit (-1 as int32) where nothing was hit.
template <int W>
struct PacketHit {
  vfloat<W> t;   ///< hit distance, +inf for a miss
  vfloat<W> u;   ///< barycentric of v1
  vfloat<W> v;   ///< barycentric of v2
  vint<W> prim;  ///< triangle number
};

/// A packet of misses (t = +inf, prim = kNoHit, u = v = 0).
template <int W>
inline PacketHit<W> packet_miss() {
  return {splat<W>(std::numeric_limits<float>::infinity()), splat<W>(0.0f), splat<W>(0.0f),
          splat_int<W>(-1)};
}

/// Ray `lane` of a packet, as a scalar Ray.
template <int W>
inline Ray packet_lane(const RayPacket<W>& p, int lane) {
  Ray r;
  r.org = {p.org[0][lane], p.org[1][lane], p.org[2][lane]};
  r.dir = {p.dir[0][lane], p.dir[1][lane], p.dir[2][lane]};
  r.tnear = p.tnear[lane];
  r.tfar = p.tfar[lane];
  return r;
}

/// is_valid (geometry/ray.h) of W lanes: finite origin and direction, a
/// non-zero direction, tnear <= tfar (false when either is NaN).
template <int W>
inline vmask<W> valid_lanes(const vfloat<W> (&org)[3], const vfloat<W> (&dir)[3], vfloat<W> tnear,
                            vfloat<W> tfar) {
  const float big = std::numeric_limits<float>::max();
  vmask<W> valid = tnear <= tfar;
  for (int k = 0; k < 3; ++k) valid &= (abs<W>(org[k]) <= big) & (abs<W>(dir[k]) <= big);
  return valid & ((dir[0] != 0.0f) | (dir[1] != 0.0f) | (dir[2] != 0.0f));
}

namespace watertight_detail {
/// Component k[i] of a per lane.
template <int W>
inline vfloat<W> pick(const vfloat<W> (&a)[3], vint<W> k) {
  return k == 0 ? a[0] : (k == 1 ? a[1] : a[2]);
}
}  // namespace watertight_detail

/// Precomputes a packet of W rays in SoA form; lanes failing valid_lanes are
/// invalid. watertight_precompute on vectors: the same axis choice
/// (max_axis) and the same divisions, so each valid lane equals the scalar
/// precomputation; invalid lanes are never tested.
template <int W>
inline WatertightPacket<W> watertight_precompute_soa(const vfloat<W> (&org)[3], const vfloat<W> (&dir)[3],
                                                    vfloat<W> tnear, vfloat<W> tfar) {
  WatertightPacket<W> p{};
  for (int k = 0; k < 3; ++k) p.org[k] = org[k];
  p.tnear = tnear, p.tfar = tfar;
  p.valid = valid_lanes<W>(p.org, dir, p.tnear, p.tfar);
  // max_axis: x if |x| >= |y| and |x| >= |z|, else y if |y| >= |z|, else z.
  const vfloat<W> ax = abs<W>(dir[0]), ay = abs<W>(dir[1]), az = abs<W>(dir[2]);
  const vmask<W> xy = ax >= ay;
  const vint<W> kz = (xy & (ax >= az)) ? splat_int<W>(0) : ((~xy & (ay >= az)) ? splat_int<W>(1) : splat_int<W>(2));
  vint<W> kx = kz == 2 ? splat_int<W>(0) : kz + 1;
  vint<W> ky = kx == 2 ? splat_int<W>(0) : kx + 1;
  const vfloat<W> dz = watertight_detail::pick<W>(dir, kz);
  const vmask<W> swap = dz < 0.0f;
  const vint<W> kx_swapped = swap ? ky : kx;
  ky = swap ? kx : ky;
  kx = kx_swapped;
  p.sx = watertight_detail::pick<W>(dir, kx) / dz;
  p.sy = watertight_detail::pick<W>(dir, ky) / dz;
  p.sz = 1.0f / dz;
  p.kx0 = kx == 0, p.kx1 = kx == 1, p.ky0 = ky == 0, p.ky1 = ky == 1, p.kz0 = kz == 0, p.kz1 = kz == 1;
  const unsigned vm = movemask<W>(p.valid);
  p.uniform = true;
  if (vm != 0) {
    const int i0 = __builtin_ctz(vm);
    p.kx = kx[i0], p.ky = ky[i0], p.kz = kz[i0];
    const vmask<W> same = (kx == p.kx) & (ky == p.ky) & (kz == p.kz);
    p.uniform = (movemask<W>(same) & vm) == vm;
  }
  return p;
}

/// The same from AoS rays; lanes past the end have a zero direction (not valid).
template <int W>
inline WatertightPacket<W> watertight_precompute_packet(std::span<const Ray> rays) {
  vfloat<W> org[3] = {}, dir[3] = {};
  vfloat<W> tnear = {}, tfar = splat<W>(std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < rays.size() && i < std::size_t(W); ++i) {
    for (int k = 0; k < 3; ++k) org[k][i] = rays[i].org[k], dir[k][i] = rays[i].dir[k];
    tnear[i] = rays[i].tnear, tfar[i] = rays[i].tfar;
  }
  return watertight_precompute_soa<W>(org, dir, tnear, tfar);
}

/// Precomputes a packet from SoA rays; lanes off in `active` are invalid.
template <int W>
inline WatertightPacket<W> watertight_precompute_packet(const RayPacket<W>& rays, vmask<W> active) {
  Ray lanes[W];
  for (int i = 0; i < W; ++i) {
    lanes[i] = packet_lane(rays, i);
    if (!active[i]) lanes[i].tnear = std::numeric_limits<float>::quiet_NaN();  // makes it invalid
  }
  return watertight_precompute_packet<W>(std::span<const Ray>(lanes, std::size_t(W)));
}

namespace watertight_detail {
/// Component k of a vertex relative to the origin, k given per lane by masks.
template <int W>
inline vfloat<W> pick_axis(const vfloat<W> (&a)[3], vmask<W> is0, vmask<W> is1) {
  return is0 ? a[0] : (is1 ? a[1] : a[2]);
}

/// Lanes of `need` get the double-precision edge functions of
/// watertight_edges_double, computed for all W lanes at once in double
/// vectors: the products of floats are exact in double and each difference is
/// rounded to double, then to float, as the scalar function does, so every
/// lane is the scalar fallback's bit for bit (a loop over the lanes, with an
/// extract and a branch per lane, made bunny vertex rays of `bvh8-float` about
/// 4 % slower; docs/notes/2026-12-07-mesh-query-and-kd-step-bound.md). Test:
/// "watertight: the vector double fallback equals the scalar one".
template <int W>
inline void edges_double_lanes(vmask<W> need, const vfloat<W>& ax, const vfloat<W>& ay,
                               const vfloat<W>& bx, const vfloat<W>& by, const vfloat<W>& cx,
                               const vfloat<W>& cy, vfloat<W>& u, vfloat<W>& v, vfloat<W>& w) {
  using D = vdouble<W>;  // converted in place: no function returns a vector (the base ISA's ABI)
  const D dax = __builtin_convertvector(ax, D), day = __builtin_convertvector(ay, D);
  const D dbx = __builtin_convertvector(bx, D), dby = __builtin_convertvector(by, D);
  const D dcx = __builtin_convertvector(cx, D), dcy = __builtin_convertvector(cy, D);
  const vfloat<W> ud = __builtin_convertvector(dcx * dby - dcy * dbx, vfloat<W>);
  const vfloat<W> vd = __builtin_convertvector(dax * dcy - day * dcx, vfloat<W>);
  const vfloat<W> wd = __builtin_convertvector(dbx * day - dby * dax, vfloat<W>);
  u = need ? ud : u, v = need ? vd : v, w = need ? wd : w;
}
}  // namespace watertight_detail

/// Watertight test of W rays against triangle (v0, v1, v2) numbered `prim`.
/// Lanes in `active` (and valid) whose hit t is in [tnear, tfar], finite and
/// strictly below hit.t get hit.t/u/v/prim replaced. Returns those lanes.
template <int W>
inline vmask<W> intersect_packet(const WatertightPacket<W>& r, const Vec3f& v0, const Vec3f& v1,
                                 const Vec3f& v2, std::uint32_t prim, PacketHit<W>& hit,
                                 vmask<W> active) {
  active &= r.valid;
  const vfloat<W> a[3] = {v0.x - r.org[0], v0.y - r.org[1], v0.z - r.org[2]};
  const vfloat<W> b[3] = {v1.x - r.org[0], v1.y - r.org[1], v1.z - r.org[2]};
  const vfloat<W> c[3] = {v2.x - r.org[0], v2.y - r.org[1], v2.z - r.org[2]};
  vfloat<W> akx, aky, akz, bkx, bky, bkz, ckx, cky, ckz;
  if (r.uniform) {
    akx = a[r.kx], aky = a[r.ky], akz = a[r.kz];
    bkx = b[r.kx], bky = b[r.ky], bkz = b[r.kz];
    ckx = c[r.kx], cky = c[r.ky], ckz = c[r.kz];
  } else {
    using watertight_detail::pick_axis;
    akx = pick_axis<W>(a, r.kx0, r.kx1), aky = pick_axis<W>(a, r.ky0, r.ky1), akz = pick_axis<W>(a, r.kz0, r.kz1);
    bkx = pick_axis<W>(b, r.kx0, r.kx1), bky = pick_axis<W>(b, r.ky0, r.ky1), bkz = pick_axis<W>(b, r.kz0, r.kz1);
    ckx = pick_axis<W>(c, r.kx0, r.kx1), cky = pick_axis<W>(c, r.ky0, r.ky1), ckz = pick_axis<W>(c, r.kz0, r.kz1);
  }
  const vfloat<W> ax = akx - no_fma(r.sx * akz), ay = aky - no_fma(r.sy * akz);
  const vfloat<W> bx = bkx - no_fma(r.sx * bkz), by = bky - no_fma(r.sy * bkz);
  const vfloat<W> cx = ckx - no_fma(r.sx * ckz), cy = cky - no_fma(r.sy * ckz);
  vfloat<W> u = no_fma(cx * by) - no_fma(cy * bx);
  vfloat<W> v = no_fma(ax * cy) - no_fma(ay * cx);
  vfloat<W> w = no_fma(bx * ay) - no_fma(by * ax);
  const vmask<W> zero = active & ((u == 0.0f) | (v == 0.0f) | (w == 0.0f));
  if (any<W>(zero)) watertight_detail::edges_double_lanes<W>(zero, ax, ay, bx, by, cx, cy, u, v, w);
  const vmask<W> neg = (u < 0.0f) | (v < 0.0f) | (w < 0.0f);
  const vmask<W> pos = (u > 0.0f) | (v > 0.0f) | (w > 0.0f);
  active &= ~(neg & pos);
  if (none<W>(active)) return active;
  const vfloat<W> det = u + v + w;
  const vfloat<W> tz = no_fma(u * (r.sz * akz)) + no_fma(v * (r.sz * bkz)) + no_fma(w * (r.sz * ckz));
  const vfloat<W> t = tz / select<W>(active, det, splat<W>(1.0f));
  active &= (det != 0.0f) & (t >= r.tnear) & (t <= r.tfar) &
            (t < std::numeric_limits<float>::infinity()) & (t < hit.t);
  if (none<W>(active)) return active;
  const vfloat<W> rcp = 1.0f / select<W>(active, det, splat<W>(1.0f));
  hit.t = select<W>(active, t, hit.t);
  hit.u = select<W>(active, v * rcp, hit.u);
  hit.v = select<W>(active, w * rcp, hit.v);
  hit.prim = select<W>(active, splat_int<W>(std::int32_t(prim)), hit.prim);
  return active;
}

/// Writes lanes 0..hits.size()-1 of a packet result as Hit records.
template <int W>
inline void store_hits(const PacketHit<W>& h, std::span<Hit> hits) {
  for (std::size_t i = 0; i < hits.size() && i < std::size_t(W); ++i) {
    hits[i].t = h.t[i];
    hits[i].prim = std::uint32_t(h.prim[i]);
    hits[i].u = h.u[i];
    hits[i].v = h.v[i];
  }
}

}  // namespace BSPRT_ISA_NAMESPACE
}  // namespace bsprt::simd
