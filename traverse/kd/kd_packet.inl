/// \file kd_packet.inl
/// The one source of the kd packet kernel (Wald's coherent packet traversal),
/// included by kd_packet_{sse42,avx2,avx512}.cpp with their ISA flags and
/// widths. Not a header: include it once per kernel translation unit.
///
/// Every lane runs exactly the steps of trace_single (kd_traverse.cpp) with the
/// same IEEE operations: same widened t, same near/far (the packet needs equal
/// direction signs, else its rays go single), same culling, same leaf order.
/// A lane that goes only to the far child while others go near waits on the
/// stack as "direct" (no cull, no clamp on pop), as trace_single goes there
/// without a stack entry. Hence hits and counters equal single rays exactly.
/// Raw arrays only: no std:: templates are instantiated for this ISA.

#include <bit>
#include <cstdint>
#include <limits>
#include <span>

#include "traverse/kd/kd_kernel.h"
#include "traverse/simd/exact_packet_filter.h"
#include "traverse/simd/exact_packet_stage.h"
#include "traverse/simd/watertight_packet.h"

namespace bsprt::simd {
inline namespace BSPRT_ISA_NAMESPACE {
namespace {

using detail::KdView;

template <int W>
struct KdPacketEntry {
  std::uint32_t node;
  vfloat<W> tmin, tmax;
  vmask<W> active;  ///< lanes that go into this cell
  vmask<W> popped;  ///< of those, lanes that also went near (real stack entries)
};

template <int W>
inline std::uint64_t lanes(vmask<W> m) {
  return std::uint64_t(__builtin_popcount(movemask<W>(m)));
}

/// Sign bit of each axis shared by all valid lanes; false when they differ.
template <int W>
inline bool coherent_signs(const Ray* rays, int count, vmask<W> valid, bool neg[3]) {
  bool first = true;
  for (int i = 0; i < count; ++i) {
    if (!valid[i]) continue;
    const bool s[3] = {__builtin_signbit(rays[i].dir.x) != 0, __builtin_signbit(rays[i].dir.y) != 0,
                       __builtin_signbit(rays[i].dir.z) != 0};
    for (int k = 0; k < 3; ++k) {
      if (first) neg[k] = s[k];
      else if (neg[k] != s[k]) return false;
    }
    first = false;
  }
  return true;
}

/// Widened t: lo = min(t*kKdTLo, t*kKdTHi), hi = max(...), as trace_single.
template <int W>
inline void widen(vfloat<W> t, vfloat<W>& lo, vfloat<W>& hi) {
  const vfloat<W> a = t * detail::kKdTLo, b = t * detail::kKdTHi;
  lo = a < b ? a : b;
  hi = a > b ? a : b;
}

/// The exact leaf test (v.exact_leaf) for the active lanes: each triangle
/// against all of them in the packet prefilter (exact_packet_filter.h), then,
/// in leaf order, the scalar exact test for the lanes it could not prove
/// missed. A lane sees its triangles in the order the one-ray test sees them,
/// less certain misses, which change nothing, so its NearestHit (the exact
/// order and the answer) is the single ray's; hit.t becomes its cull bound
/// (cull_bound). `er` holds each lane's double constants, made on first use.
/// Never counted (counted runs trace single rays).
template <int W>
inline void packet_exact_leaf(const KdView& v, const KdNode& n, const WatertightPacket<W>& pre, vmask<W> filterable,
                              const PacketExactRays<W>& pr, const Ray* rays, NearestHit* nearest,
                              detail::LazyExactRay* er, PacketHit<W>& hit, vmask<W> active) {
  const std::uint32_t first = n.prim_offset(), end = first + n.prim_count();
  unsigned changed = 0;  // lanes whose nearest hit's cull bound moved
  for (std::uint32_t i = first; i < end; ++i) {
    const KdTriangle& t = v.triangles[v.prims[i]];
    const unsigned need = movemask<W>(exact_packet_lanes<W>(pre, t.v[0], t.v[1], t.v[2], active, filterable));
    changed |= packet_exact_triangle<W>(*v.exact_leaf, pr, rays, er, nearest, need, v.prims + i, t);
  }
  if (changed == 0) return;
  alignas(64) float tl[W];
  store<W>(tl, hit.t);
  for (unsigned m = changed; m != 0; m &= m - 1) {
    const int lane = std::countr_zero(m);
    tl[lane] = cull_bound(nearest[lane]);
  }
  hit.t = load<W>(tl);
}

template <int W, bool kCount>
inline void packet_leaf(const KdView& v, const KdNode& n, const WatertightPacket<W>& pre,
                        PacketHit<W>& hit, vmask<W> active, RayCounters* c) {
  const std::uint32_t first = n.prim_offset(), end = first + n.prim_count();
  if constexpr (kCount) {
    const std::uint64_t a = lanes<W>(active);
    c->leaf_visits += a;
    c->triangle_tests += a * n.prim_count();
  }
  for (std::uint32_t i = first; i < end; ++i) {
    const std::uint32_t p = v.prims[i];
    const KdTriangle& t = v.triangles[p];
    intersect_packet<W>(pre, t.v[0], t.v[1], t.v[2], p, hit, active);
  }
}

/// W rays in SoA form; lanes past the packet's rays have a zero direction.
template <int W>
struct KdPacketLanes {
  vfloat<W> o[3] = {}, dir[3] = {}, tnear = {}, tfar = {};
  vmask<W> valid;  ///< valid_lanes: padding lanes are not valid
};

/// Traverses one coherent packet; lanes not valid stay misses. The triangle
/// test's precomputation is made at the first leaf: most packets of a camera
/// that frames the scene never reach one.
template <int W, bool kCount>
void trace_packet(const KdView& v, const KdPacketLanes<W>& r, const bool neg[3], PacketHit<W>& hit,
                  RayCounters* c, const Ray* rays = nullptr, NearestHit* nearest = nullptr,
                  detail::LazyExactRay* er = nullptr) {
  WatertightPacket<W> pre;
  vmask<W> filterable{};  // exact leaves: lanes the packet prefilter may leave out
  PacketExactRays<W> pr;   // exact leaves: the lanes' double constants, for the vector double stage
  bool have_pre = false;
  const vfloat<W>(&o)[3] = r.o;
  vfloat<W> inv[3], tmin = r.tnear, tmax = r.tfar;
  for (int k = 0; k < 3; ++k) {  // detail::kd_reciprocal per lane; padding lanes: inf, never active
    const vmask<W> normal_or_zero = (r.dir[k] == 0.0f) | (abs<W>(r.dir[k]) >= 0x1p-126f);
    // detail::kd_reach, written out: no std:: or detail:: function outside the ISA namespace here (simd.h).
    const float lo = v.bounds.lo[k] < 0 ? -v.bounds.lo[k] : v.bounds.lo[k];
    const float hi = v.bounds.hi[k] < 0 ? -v.bounds.hi[k] : v.bounds.hi[k];
    const vmask<W> no_overflow = abs<W>(o[k]) + (lo > hi ? lo : hi) < 0x1p127f;
    inv[k] = select<W>(normal_or_zero & no_overflow, 1.0f / r.dir[k],
                       splat<W>(std::numeric_limits<float>::quiet_NaN()));
  }
  for (int k = 0; k < 3; ++k) {  // clip_root
    const vfloat<W> t0 = (v.bounds.lo[k] - o[k]) * inv[k], t1 = (v.bounds.hi[k] - o[k]) * inv[k];
    vfloat<W> enter, exit, unused;
    widen<W>(neg[k] ? t1 : t0, enter, unused);
    widen<W>(neg[k] ? t0 : t1, unused, exit);
    tmin = enter > tmin ? enter : tmin;
    tmax = exit < tmax ? exit : tmax;
  }
  vmask<W> active = r.valid & (tmin <= tmax);
  if (none<W>(active)) return;
  KdPacketEntry<W> stack[kKdMaxDepth];
  int sp = 0;
  std::uint32_t node = 0;
  for (;;) {
    const KdNode* n = &v.nodes[node];
    while (!n->is_leaf()) {
      __builtin_prefetch(&v.nodes[n->upper_child()]);  // as the single-ray step
      if constexpr (kCount) c->kd_node_visits += lanes<W>(active);
      const int k = n->axis();
      vfloat<W> tl, th;
      widen<W>((n->split - o[k]) * inv[k], tl, th);
      const std::uint32_t lower = node + 1, upper = n->upper_child();
      const std::uint32_t near = neg[k] ? upper : lower, far = neg[k] ? lower : upper;
      const vmask<W> go_near = active & ~(th < tmin), go_far = active & ~(tl > tmax);
      const vfloat<W> near_max = th < tmax ? th : tmax, far_min = tl > tmin ? tl : tmin;
      if (any<W>(go_far)) {
        if (any<W>(go_near)) {
          stack[sp++] = {far, far_min, tmax, go_far, go_far & go_near};
          node = near, tmax = near_max, active = go_near;
        } else {
          node = far, tmin = far_min, active = go_far;
        }
      } else if (any<W>(go_near)) {
        node = near, tmax = near_max, active = go_near;
      } else {
        break;
      }
      n = &v.nodes[node];
    }
    const unsigned am = movemask<W>(active);
    if (n->is_leaf() && nearest && am != 0 && (am & (am - 1)) == 0) {  // exact leaves, one lane: the scalar test
      const int lane = std::countr_zero(am);
      if (n->prim_count() != 0) {  // an empty leaf changes nothing
        const WatertightRay wr = watertight_precompute(rays[lane]);
        detail::kd_exact_leaf(v, n->prim_offset(), n->prim_offset() + n->prim_count(), rays[lane], wr,
                              detail::filterable(wr, rays[lane]), er[lane], nearest[lane], nullptr);
      }
      hit.t[lane] = cull_bound(nearest[lane]);
    } else if (n->is_leaf()) {
      if (!have_pre) {  // the packet's constants, at its first leaf of two or more lanes
        pre = watertight_precompute_soa<W>(r.o, r.dir, r.tnear, r.tfar);
        if (nearest) {
          filterable = filterable_lanes<W>(pre, r.dir);
          packet_exact_rays<W>(rays, movemask<W>(r.valid), pr);
        }
        have_pre = true;
      }
      if (nearest)
        packet_exact_leaf<W>(v, *n, pre, filterable, pr, rays, nearest, er, hit, active);
      else
        packet_leaf<W, kCount>(v, *n, pre, hit, active, c);
    }
    for (;;) {
      if (sp == 0) return;
      const KdPacketEntry<W>& e = stack[--sp];
      // Lanes with a real stack entry: skip past the nearest hit, clamp tmax.
      active = e.active & ~(e.popped & (e.tmin > hit.t));
      if (none<W>(active)) continue;
      node = e.node, tmin = e.tmin;
      tmax = (e.popped & (hit.t < e.tmax)) ? hit.t : e.tmax;
      break;
    }
  }
}

template <int W, bool kCount>
void trace_packets(const KdView& v, const Ray* rays, std::size_t n, Hit* hits, RayCounters* c,
                   detail::KdSingleFn single) {
  for (std::size_t base = 0; base < n; base += W) {
    const int count = n - base < std::size_t(W) ? int(n - base) : W;
    KdPacketLanes<W> r;
    for (int i = 0; i < count; ++i) {
      const Ray& ray = rays[base + i];
      for (int k = 0; k < 3; ++k) r.o[k][i] = ray.org[k], r.dir[k][i] = ray.dir[k];
      r.tnear[i] = ray.tnear, r.tfar[i] = ray.tfar;
    }
    r.valid = valid_lanes<W>(r.o, r.dir, r.tnear, r.tfar);
    bool neg[3] = {false, false, false};
    if (!coherent_signs<W>(rays + base, count, r.valid, neg)) {
      for (int i = 0; i < count; ++i) hits[base + i] = single(v, rays[base + i], c);
      continue;
    }
    if constexpr (kCount) c->rays += std::uint64_t(count);
    PacketHit<W> hit = packet_miss<W>();
    if (v.exact_leaf) {  // exact leaves: never counted here (see packet_exact_leaf)
      NearestHit nearest[W];
      detail::LazyExactRay er[W];
      if (any<W>(r.valid)) trace_packet<W, false>(v, r, neg, hit, nullptr, rays + base, nearest, er);
      for (int i = 0; i < count; ++i) hits[base + std::size_t(i)] = nearest[i].hit;
      continue;
    }
    if (any<W>(r.valid)) trace_packet<W, kCount>(v, r, neg, hit, c);
    store_hits<W>(hit, std::span<Hit>(hits + base, std::size_t(count)));
  }
}

template <int W>
void trace_packets_counted(const KdView& v, const Ray* rays, std::size_t n, Hit* hits,
                           RayCounters* c, detail::KdSingleFn single) {
  if (c) trace_packets<W, true>(v, rays, n, hits, c, single);
  else trace_packets<W, false>(v, rays, n, hits, nullptr, single);
}

}  // namespace
}  // namespace BSPRT_ISA_NAMESPACE
}  // namespace bsprt::simd
