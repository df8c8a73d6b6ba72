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

#include <cstdint>

#include "traverse/bsp_kernel.h"
#include "traverse/watertight_packet.h"

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

/// Per-lane constants of bsp_ray_setup in SoA form.
template <int W>
struct BspPacketRay {
  vfloat<W> o[3], dir[3], inv[3];
  vmask<W> neg[3];
  vfloat<W> err_o, err_d;
  vfloat<W> tmin, tmax;
  vmask<W> live;
};

template <int W>
inline std::uint64_t lanes(vmask<W> m) {
  return std::uint64_t(__builtin_popcount(movemask<W>(m)));
}

/// Lanes from the scalar setup, so every value is the single ray's.
template <int W>
inline BspPacketRay<W> packet_setup(const BspView& v, const Ray* rays, int count) {
  BspPacketRay<W> p{};
  for (int i = 0; i < W; ++i) {
    BspRayConst c{};
    if (i < count) c = detail::bsp_ray_setup(rays[i], v.bounds, v.certified);
    for (int k = 0; k < 3; ++k) {
      p.o[k][i] = c.o[k], p.dir[k][i] = c.dir[k], p.inv[k][i] = c.inv[k];
      p.neg[k][i] = c.neg[k] ? -1 : 0;
    }
    p.err_o[i] = c.err_o, p.err_d[i] = c.err_d;
    p.tmin[i] = c.tmin, p.tmax[i] = c.tmax;
    p.live[i] = c.live ? -1 : 0;
  }
  return p;
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

/// The node step for all lanes: conservative near_hi / far_lo, and the lanes
/// whose near child is the second one.
template <int W>
inline vmask<W> cut_node(const CompactBspSlot& n, const BspPacketRay<W>& r, vfloat<W> tmin,
                         vfloat<W> tmax, vfloat<W>& near_hi, vfloat<W>& far_lo) {
  if (n.is_plane()) {
    const vfloat<W> b = detail::plane_cut<vfloat<W>>(&n, r.o, r.dir, r.err_o, r.err_d, tmin, tmax,
                                                     near_hi, far_lo);
    return b < 0.0f;
  }
  const int k = n.axis();
  detail::kd_cut<vfloat<W>>(n.split(), r.o[k], r.inv[k], near_hi, far_lo);
  return r.neg[k];
}

/// Traverses one packet; lanes not live stay misses.
template <int W, bool kCount>
void trace_packet(const BspView& v, const BspPacketRay<W>& r, const WatertightPacket<W>& pre,
                  PacketHit<W>& hit, RayCounters* c) {
  vfloat<W> tmin = r.tmin, tmax = r.tmax;
  vmask<W> active = r.live;
  BspPacketEntry<W> stack[kBspPacketStack];
  int sp = 0;
  std::uint32_t node = 0;
  for (;;) {
    const CompactBspSlot* n = &v.nodes[node];
    bool leaf = true;
    while (!n->is_leaf()) {
      vfloat<W> near_hi, far_lo;
      const vmask<W> flip = cut_node<W>(*n, r, tmin, tmax, near_hi, far_lo);
      const unsigned am = movemask<W>(active), fm = movemask<W>(active & flip);
      bool fl = fm != 0;
      if (fl && fm != am) {  // disagreeing lanes redo this node later
        fl = (fm & (am & (0u - am))) != 0;  // the lowest active lane decides
        const vmask<W> keep = fl ? (active & flip) : (active & ~flip);
        stack[sp++] = {node, tmin, tmax, active & ~keep, mask_false<W>()};
        active = keep;
      }
      if constexpr (kCount) {
        if (n->is_plane()) c->bsp_node_visits += lanes<W>(active);
        else c->kd_node_visits += lanes<W>(active);
      }
      const std::uint32_t first = node + n->slots(), second = n->second_child();
      const std::uint32_t near = fl ? second : first, far = fl ? first : second;
      // A child that lists no triangle is not stored (bsp_compact.h): no lane goes there.
      const bool near_empty = fl ? n->second_empty() : n->first_empty();
      const bool far_empty = fl ? n->first_empty() : n->second_empty();
      const vmask<W> go_near = near_empty ? mask_false<W>() : active & ~(near_hi < tmin);
      const vmask<W> go_far = far_empty ? mask_false<W>() : active & ~(far_lo > tmax);
      const vfloat<W> near_max = near_hi < tmax ? near_hi : tmax;
      const vfloat<W> far_min = far_lo > tmin ? far_lo : tmin;
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
        leaf = false;
        break;
      }
      n = &v.nodes[node];
    }
    if (leaf) packet_leaf<W, kCount>(v, *n, pre, hit, active, c);
    for (;;) {
      if (sp == 0) return;
      const BspPacketEntry<W>& e = stack[--sp];
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
void trace_packets(const BspView& v, const Ray* rays, std::size_t n, Hit* hits, RayCounters* c) {
  for (std::size_t base = 0; base < n; base += W) {
    const int count = n - base < std::size_t(W) ? int(n - base) : W;
    const WatertightPacket<W> pre =
        watertight_precompute_packet<W>(std::span<const Ray>(rays + base, std::size_t(count)));
    const BspPacketRay<W> r = packet_setup<W>(v, rays + base, count);
    if constexpr (kCount) c->rays += std::uint64_t(count);
    PacketHit<W> hit = packet_miss<W>();
    if (any<W>(r.live)) trace_packet<W, kCount>(v, r, pre, hit, c);
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
