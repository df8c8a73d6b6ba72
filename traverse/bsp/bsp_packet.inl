/// \file bsp_packet.inl
/// The one source of the BSP packet kernel, included by
/// bsp_packet_{sse42,avx2,avx512}.cpp with their ISA flags and widths. Not a
/// header: include it once per kernel translation unit.
///
/// Every lane runs exactly the steps of trace_single (bsp_traverse.cpp) with
/// the same IEEE operations (bsp_kernel.h, -ffp-contract=off): same intervals,
/// same near/far, same culling, same leaf order. Two devices keep the order:
/// (1) a lane that goes only to the far child while others go near waits on
/// the stack as "direct" (no cull, no clamp on pop), as trace_single goes there
/// without a stack entry (the kd kernel's scheme); (2) at a node where lanes
/// disagree on the near child (signs of n·dir differ, or of dir_k), the lanes
/// that disagree with the lowest active lane wait on the stack *at that node*
/// as a direct entry and redo it later. A waiting lane's state (interval,
/// nearest hit) does not change meanwhile, so each lane sees the single-ray
/// sequence of nodes and leaves: hits and counters equal single rays exactly.
/// Raw arrays only: no std:: templates are instantiated for this ISA.

#include <bit>
#include <cstdint>
#include <limits>
#include <span>

#include "traverse/bsp/bsp_kernel.h"
#include "traverse/exact_double_stage.h"
#include "traverse/simd/exact_packet_filter.h"
#include "traverse/simd/exact_packet_stage.h"
#include "traverse/simd/watertight_packet.h"

namespace bsprt::simd {
inline namespace BSPRT_ISA_NAMESPACE {
namespace {

using detail::BspRayConst;
using detail::BspView;

/// Stack bound: per level one far child and one deferred node.
constexpr int kBspPacketStack = 2 * kBspMaxDepth + 4;

template <int W>
struct BspPacketEntry {
  std::uint32_t node;
  vfloat<W> tmin, tmax;
  vmask<W> active;  ///< lanes that go into this node
  vmask<W> popped;  ///< of those, lanes with a real (single-ray) stack entry
};

/// Per-lane constants of bsp_ray_setup in SoA form, and the rays' own
/// segments (tnear, tfar) for the triangle test.
template <int W>
struct BspPacketRay {
  vfloat<W> o[3], dir[3], inv[3];
  vfloat<W> tdir[3];  ///< direction of the traversal (dir, or scaled by detail::scale_direction)
  vmask<W> neg[3];
  vfloat<W> err;
  vfloat<W> tmin, tmax;
  vfloat<W> tnear, tfar;
  vmask<W> live;
  vmask<W> scaled;      ///< lanes traversed in scaled parameters
  vfloat<W> hit_scale;  ///< 2^e of those lanes, 1 elsewhere
  bool any_scaled;      ///< some lane is scaled
  /// Per axis: 0 when no live lane's neg is set, 1 when every live lane's is,
  /// 2 when they differ. Below 2, kd nodes on that axis take the kd step.
  std::uint8_t kd_sign[3];
};

template <int W>
inline std::uint64_t lanes(vmask<W> m) {
  return std::uint64_t(__builtin_popcount(movemask<W>(m)));
}

/// bsp_ray_setup for W lanes at once (ray_setup_core on vectors). Lanes past
/// `count` or with an invalid ray are not live; their other values are
/// meaningless and never read.
template <int W>
inline BspPacketRay<W> packet_setup(const BspView& v, const Ray* rays, int count) {
  BspPacketRay<W> p{};  // lanes past count: zero direction, so not valid
  for (int i = 0; i < count; ++i) {
    const Ray& ray = rays[i];
    for (int k = 0; k < 3; ++k) p.o[k][i] = ray.org[k], p.dir[k][i] = ray.dir[k];
    p.tmin[i] = ray.tnear, p.tmax[i] = ray.tfar;
  }
  p.tnear = p.tmin, p.tfar = p.tmax;
  p.hit_scale = splat<W>(1.0f);
  for (int k = 0; k < 3; ++k) p.tdir[k] = p.dir[k];
  // A direction out of range (rare): bsp_ray_setup's scalar scale_direction,
  // lane by lane. An invalid lane is never live, so whether it was scaled
  // does not matter.
  vfloat<W> md{};
  for (int k = 0; k < 3; ++k) md = abs<W>(p.dir[k]) > md ? abs<W>(p.dir[k]) : md;
  const unsigned out = movemask<W>(~((md <= detail::kSafeMax) & (md >= detail::kSafeMinDir)));
  for (unsigned m = out & ((1u << count) - 1u); m != 0; m &= m - 1) {
    const int i = __builtin_ctz(m);
    float o[3], d[3], t0 = p.tnear[i], t1 = p.tfar[i], scale = 1.0f;
    for (int k = 0; k < 3; ++k) o[k] = p.o[k][i], d[k] = p.dir[k][i];
    if (!detail::scale_direction(o, d, t0, t1, scale)) continue;
    for (int k = 0; k < 3; ++k) p.tdir[k][i] = d[k];
    p.tmin[i] = t0, p.tmax[i] = t1, p.scaled[i] = -1, p.hit_scale[i] = scale;
    p.any_scaled = true;
  }
  const vmask<W> valid = valid_lanes<W>(p.o, p.dir, p.tnear, p.tfar);
  detail::ray_setup_core(p.o, p.tdir, v.bounds, v.certified, p.inv, p.neg, p.tmin, p.tmax, p.err);
  p.live = valid & (p.tmin <= p.tmax);
  const unsigned live = movemask<W>(p.live);
  for (int k = 0; k < 3; ++k) {
    const unsigned m = movemask<W>(p.neg[k] & p.live);
    p.kd_sign[k] = std::uint8_t(m == 0 ? 0 : (m == live ? 1 : 2));
  }
  return p;
}

/// The exact leaf test (v.exact_leaf) for the active lanes: each triangle
/// against all of them in the packet prefilter (exact_packet_filter.h), then,
/// in leaf order, the scalar exact test for the lanes it could not prove
/// missed. A lane sees its triangles in the order the one-ray test sees them,
/// less certain misses, which change nothing, so its NearestHit (the exact
/// order and the answer) is the single ray's; hit.t becomes its cull bound
/// (cull_bound). `er` holds each lane's double constants, made on first use.
/// Counted runs trace single rays (BspTracer::trace_batch), so no counters here.
template <int W>
inline void packet_exact_leaf(const BspView& v, const CompactBspSlot& n, const WatertightPacket<W>& pre,
                              vmask<W> filterable, const PacketExactRays<W>& pr, const Ray* rays,
                              NearestHit* nearest, detail::LazyExactRay* er, PacketHit<W>& hit, vmask<W> active) {
  const std::uint32_t first = n.prim_offset(), count = n.prim_count();
  unsigned changed = 0;  // lanes whose nearest hit's cull bound moved
  for (std::uint32_t i = first; i < first + count; ++i) {
    const BspTriangle& t = v.triangles[i];
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
inline void packet_leaf(const BspView& v, const CompactBspSlot& n, const WatertightPacket<W>& pre,
                        PacketHit<W>& hit, vmask<W> active, RayCounters* c) {
  const std::uint32_t first = n.prim_offset(), end = first + n.prim_count();
  if constexpr (kCount) {
    const std::uint64_t a = lanes<W>(active);
    c->leaf_visits += a;
    c->triangle_tests += a * n.prim_count();
  }
  for (std::uint32_t i = first; i < end; ++i) {
    const BspTriangle& t = v.triangles[i];
    intersect_packet<W>(pre, t.v[0], t.v[1], t.v[2], v.prims[i], hit, active);
  }
}

/// Traverses one packet; lanes not live stay misses. The triangle test's
/// precomputation is made at the first leaf: most packets of a camera that
/// frames the scene never reach one.
template <int W, bool kCount, detail::Order kOrder>
void trace_packet(const BspView& v, const BspPacketRay<W>& r, PacketHit<W>& hit, RayCounters* c,
                  const Ray* rays = nullptr, NearestHit* nearest = nullptr, detail::LazyExactRay* er = nullptr) {
  WatertightPacket<W> pre;
  vmask<W> filterable{};  // exact leaves: lanes the packet prefilter may leave out
  PacketExactRays<W> pr;   // exact leaves: the lanes' double constants, for the vector double stage
  bool have_pre = false;
  vfloat<W> tmin = r.tmin, tmax = r.tmax;
  vmask<W> active = r.live;
  const vmask<W> nonneg = r.tmin >= 0.0f;  // lanes that widen as detail::Order::NonNegative (kOrder PerLane)
  BspPacketEntry<W> stack[kBspPacketStack];
  int sp = 0;
  std::uint32_t node = 0;
  for (;;) {
    const CompactBspSlot* n = &v.nodes[node];
    bool leaf = true;
    while (!n->is_leaf()) {
      __builtin_prefetch(&v.nodes[n->second_child()]);  // as the single-ray step
      vfloat<W> near_hi, far_lo;
      // Per lane: near is the second child (flip). one_way: 0 or 1 when every
      // active lane agrees on it (false or true), -1 when they differ.
      vmask<W> flip;
      int one_way;
      if (!n->is_plane()) {
        const int k = n->axis();
        detail::kd_cut<vfloat<W>, kOrder>(n->split(), r.o[k], r.inv[k], near_hi, far_lo, nonneg);
        flip = r.neg[k];
        one_way = r.kd_sign[k] < 2 ? int(r.kd_sign[k]) : -1;  // the usual case, known per packet
      } else {
        flip = detail::plane_cut<vfloat<W>, kOrder>(n, r.o, r.tdir, r.err, near_hi, far_lo, nonneg) < 0.0f;
        one_way = -1;
      }
      if (one_way < 0) {
        const unsigned fm = movemask<W>(flip & active), am = movemask<W>(active);
        one_way = fm == 0 ? 0 : (fm == am ? 1 : -1);
      }
      if (one_way >= 0) {
        // Every active lane takes the same near child: the kd packet kernel's
        // step. It makes the decisions of the general step below for such a
        // flip (no lane redoes the node, the order is the lanes' own), without
        // its per-lane selects. It keeps its own copy of the push-and-advance
        // tail: one tail shared with the general step (the intervals chosen
        // per branch) measured 8 % slower on sponza atrium packets of 8.
        if constexpr (kCount) {
          if (n->is_plane()) c->bsp_node_visits += lanes<W>(active);
          else c->kd_node_visits += lanes<W>(active);
        }
        const bool f = one_way != 0;
        const std::uint32_t first = node + n->slots(), second = n->second_child();
        const std::uint32_t near = f ? second : first, far = f ? first : second;
        const bool near_empty = f ? n->second_empty() : n->first_empty();
        const bool far_empty = f ? n->first_empty() : n->second_empty();
        const vmask<W> go_near = near_empty ? mask_false<W>() : active & ~(near_hi < tmin);
        const vmask<W> go_far = far_empty ? mask_false<W>() : active & ~(far_lo > tmax);
        const vfloat<W> near_max = near_hi < tmax ? near_hi : tmax;
        if (any<W>(go_far)) {
          const vfloat<W> far_min = far_lo > tmin ? far_lo : tmin;
          if (any<W>(go_near)) {
            stack[sp++] = {far, far_min, tmax, go_far, go_far & go_near};
            node = near, tmax = near_max, active = go_near;
          } else {
            node = far, tmin = far_min, active = go_far;
          }
        } else if (any<W>(go_near)) {
          node = near, tmax = near_max, active = go_near;
        } else {
          leaf = false;
          break;
        }
        n = &v.nodes[node];
        continue;
      }
      // Each lane's single-ray decision, in terms of the first and second child.
      const vmask<W> go_own_near = active & ~(near_hi < tmin), go_own_far = active & ~(far_lo > tmax);
      const vfloat<W> near_max = near_hi < tmax ? near_hi : tmax;
      const vfloat<W> far_min = far_lo > tmin ? far_lo : tmin;
      // A child that lists no triangle is not stored (bsp_compact.h): no lane goes there.
      vmask<W> go1 = n->first_empty() ? mask_false<W>() : (flip ? go_own_far : go_own_near);
      vmask<W> go2 = n->second_empty() ? mask_false<W>() : (flip ? go_own_near : go_own_far);
      // Only lanes entering both children care about the order: when they
      // disagree, those not agreeing with the lowest of them redo this node later.
      const unsigned bm = movemask<W>(go1 & go2), bfm = movemask<W>(go1 & go2 & flip);
      const unsigned am = movemask<W>(active);
      const bool fl = bm != 0 ? (bfm & (bm & (0u - bm))) != 0 : (movemask<W>(active & flip) & (am & (0u - am))) != 0;
      if (bfm != 0 && bfm != bm) {
        const vmask<W> redo = go1 & go2 & (fl ? ~flip : flip);
        stack[sp++] = {node, tmin, tmax, redo, mask_false<W>()};
        active &= ~redo, go1 &= ~redo, go2 &= ~redo;
      }
      if constexpr (kCount) {
        if (n->is_plane()) c->bsp_node_visits += lanes<W>(active);
        else c->kd_node_visits += lanes<W>(active);
      }
      // Each lane keeps its own child intervals: [tmin, near_max] for its near child,
      // [far_min, tmax] for its far one.
      const vfloat<W> lo1 = flip ? far_min : tmin, hi1 = flip ? tmax : near_max;
      const vfloat<W> lo2 = flip ? tmin : far_min, hi2 = flip ? near_max : tmax;
      const std::uint32_t first = node + n->slots(), second = n->second_child();
      const std::uint32_t near = fl ? second : first, far = fl ? first : second;
      const vmask<W> go_near = fl ? go2 : go1, go_far = fl ? go1 : go2;
      if (any<W>(go_far)) {
        const vfloat<W> far_lo_t = fl ? lo1 : lo2, far_hi_t = fl ? hi1 : hi2;
        if (any<W>(go_near)) {
          // Lanes entering only the far child wait as direct entries (no cull, no clamp).
          stack[sp++] = {far, far_lo_t, far_hi_t, go_far, go_far & go_near};
          node = near, tmin = fl ? lo2 : lo1, tmax = fl ? hi2 : hi1, active = go_near;
        } else {
          node = far, tmin = far_lo_t, tmax = far_hi_t, active = go_far;
        }
      } else if (any<W>(go_near)) {
        node = near, tmin = fl ? lo2 : lo1, tmax = fl ? hi2 : hi1, active = go_near;
      } else {
        leaf = false;
        break;
      }
      n = &v.nodes[node];
    }
    const unsigned am = movemask<W>(active);
    if (leaf && nearest && am != 0 && (am & (am - 1)) == 0) {  // exact leaves, one lane: the scalar test
      const int lane = std::countr_zero(am);
      detail::exact_leaf_staged(*v.exact_leaf, rays[lane], er[lane].get(rays[lane]), v.prims + n->prim_offset(),
                                v.triangles + n->prim_offset(), n->prim_count(), nearest[lane], nullptr);
      hit.t[lane] = cull_bound(nearest[lane]);
    } else if (leaf) {
      if (!have_pre) {  // the packet's constants, at its first leaf of two or more lanes
        pre = watertight_precompute_soa<W>(r.o, r.dir, r.tnear, r.tfar);
        if (nearest) {
          filterable = filterable_lanes<W>(pre, r.dir);
          packet_exact_rays<W>(rays, movemask<W>(r.live), pr);
        }
        have_pre = true;
      }
      if (nearest)
        packet_exact_leaf<W>(v, *n, pre, filterable, pr, rays, nearest, er, hit, active);
      else
        packet_leaf<W, kCount>(v, *n, pre, hit, active, c);
    }
    // Each lane's nearest hit in its traversal parameter (detail::hit_bound).
    const vfloat<W> best =
        r.any_scaled ? detail::hit_bound<vfloat<W>, vmask<W>>(hit.t, r.scaled, r.hit_scale) : hit.t;
    for (;;) {
      if (sp == 0) return;
      const BspPacketEntry<W>& e = stack[--sp];
      // Lanes with a real stack entry: skip past the nearest hit, clamp tmax.
      active = e.active & ~(e.popped & (e.tmin > best));
      if (none<W>(active)) continue;
      node = e.node, tmin = e.tmin;
      tmax = (e.popped & (best < e.tmax)) ? best : e.tmax;
      break;
    }
  }
}

/// trace_packet with each lane widening as its single ray does (detail::Order):
/// without max and min when every live lane's segment starts at t >= 0 (camera
/// and secondary rays), else lane by lane.
template <int W, bool kCount>
void trace_packet_as(const BspView& v, const BspPacketRay<W>& r, PacketHit<W>& hit, RayCounters* c,
                     const Ray* rays = nullptr, NearestHit* nearest = nullptr, detail::LazyExactRay* er = nullptr) {
  if (none<W>(r.live & ~(r.tmin >= 0.0f)))
    trace_packet<W, kCount, detail::Order::NonNegative>(v, r, hit, c, rays, nearest, er);
  else
    trace_packet<W, kCount, detail::Order::PerLane>(v, r, hit, c, rays, nearest, er);
}

template <int W, bool kCount>
void trace_packets(const BspView& v, const Ray* rays, std::size_t n, Hit* hits, RayCounters* c) {
  for (std::size_t base = 0; base < n; base += W) {
    const int count = n - base < std::size_t(W) ? int(n - base) : W;
    const BspPacketRay<W> r = packet_setup<W>(v, rays + base, count);
    if constexpr (kCount) c->rays += std::uint64_t(count);
    PacketHit<W> hit = packet_miss<W>();
    if (v.exact_leaf) {  // exact leaves: never counted here (see packet_exact_leaf)
      NearestHit nearest[W];
      detail::LazyExactRay er[W];
      if (any<W>(r.live)) trace_packet_as<W, false>(v, r, hit, nullptr, rays + base, nearest, er);
      for (int i = 0; i < count; ++i) hits[base + std::size_t(i)] = nearest[i].hit;
      continue;
    }
    if (any<W>(r.live)) trace_packet_as<W, kCount>(v, r, hit, c);
    store_hits<W>(hit, std::span<Hit>(hits + base, std::size_t(count)));
  }
}

template <int W>
void trace_packets_counted(const BspView& v, const Ray* rays, std::size_t n, Hit* hits,
                           RayCounters* c) {
  if (c) trace_packets<W, true>(v, rays, n, hits, c);
  else trace_packets<W, false>(v, rays, n, hits, nullptr);
}

}  // namespace
}  // namespace BSPRT_ISA_NAMESPACE
}  // namespace bsprt::simd
