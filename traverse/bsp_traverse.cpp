/// \file bsp_traverse.cpp
/// Single-ray BSP traversal and the dispatcher of the packet kernels. Compiled
/// with -ffp-contract=off: bsp_packet.inl repeats these steps bit for bit.
#include "traverse/bsp_traverse.h"

#include <stdexcept>
#include <string>

#include "geometry/error.h"
#include "traverse/bsp_kernel.h"
#include "traverse/cpu_features.h"
#include "traverse/watertight.h"

namespace bsprt {
namespace {

using detail::BspRayConst;
using detail::BspView;

/// A far child waiting on the stack with the ray's (conservative) interval.
struct StackEntry {
  std::uint32_t node;
  float tmin, tmax;
};

/// Tests the triangles of a leaf (ties keep the earlier triangle). With an
/// exact leaf test, `nearest` keeps the exact order and hit mirrors it.
template <bool kCount>
inline void intersect_leaf(const BspView& v, const CompactBspSlot& n, const Ray& ray, const WatertightRay& wr,
                           Hit& hit, NearestHit& nearest, RayCounters* c) {
  const std::uint32_t first = n.prim_offset(), end = first + n.prim_count();
  if constexpr (kCount) ++c->leaf_visits;
  if (v.exact_leaf) {
    v.exact_leaf->intersect(ray, std::span<const std::uint32_t>(v.prims + first, n.prim_count()), nearest,
                            kCount ? c : nullptr);
    hit = nearest.hit;
    return;
  }
  if constexpr (kCount) c->triangle_tests += n.prim_count();
  for (std::uint32_t i = first; i < end; ++i) {
    const BspTriangle& t = v.triangles[i];
    intersect_watertight_closest(wr, t.v[0], t.v[1], t.v[2], v.prims[i], hit);
  }
}

/// One inner node: the near child's upper end and the far child's lower end
/// of the ray interval, and whether near is the second child.
template <bool kCount>
inline bool cut_node(const CompactBspSlot* n, const BspRayConst& rc, float& near_hi, float& far_lo,
                     RayCounters* c) {
  if (n->is_plane()) {
    if constexpr (kCount) ++c->bsp_node_visits;
    const float b = detail::plane_cut<float>(n, rc.o, rc.dir, rc.err, near_hi, far_lo);
    return b < 0.0f;
  }
  if constexpr (kCount) ++c->kd_node_visits;
  const int k = n->axis();
  detail::kd_cut<float>(n->split(), rc.o[k], rc.inv[k], near_hi, far_lo);
  return rc.neg[k];
}

/// Front-to-back traversal (pbrt's kd-tree loop with the paper's BSP node
/// step, made conservative). A child is culled when its conservative interval
/// is empty (NaN crossings cull nothing) or when it lists no triangle (not
/// stored, bsp_compact.h); a popped cell is skipped when it starts past the
/// nearest hit. bsp_packet.inl repeats these steps.
template <bool kCount>
Hit trace_single(const BspView& v, const Ray& ray, RayCounters* c) {
  Hit hit;
  if constexpr (kCount) ++c->rays;
  const BspRayConst rc = detail::bsp_ray_setup(ray, v.bounds, v.certified);
  if (!rc.live) return hit;
  const WatertightRay wr = watertight_precompute(ray);
  NearestHit nearest;
  float tmin = rc.tmin, tmax = rc.tmax;
  StackEntry stack[kBspMaxDepth];
  int sp = 0;
  std::uint32_t node = 0;
  for (;;) {
    const CompactBspSlot* n = &v.nodes[node];
    bool leaf = true;
    while (!n->is_leaf()) {
      // The first child follows this node; fetch the second while t is computed.
      __builtin_prefetch(&v.nodes[n->second_child()]);
      float near_hi, far_lo;
      const bool flip = cut_node<kCount>(n, rc, near_hi, far_lo, c);
      const std::uint32_t first = node + n->slots(), second = n->second_child();
      const std::uint32_t near = flip ? second : first, far = flip ? first : second;
      const bool near_empty = flip ? n->second_empty() : n->first_empty();
      const bool far_empty = flip ? n->first_empty() : n->second_empty();
      const bool go_near = !(near_hi < tmin) && !near_empty, go_far = !(far_lo > tmax) && !far_empty;  // NaN: both
      if (go_far) {
        const float far_min = far_lo > tmin ? far_lo : tmin;
        if (go_near) {
          stack[sp++] = {far, far_min, tmax};
          node = near;
          tmax = near_hi < tmax ? near_hi : tmax;
        } else {
          node = far;
          tmin = far_min;
        }
      } else if (go_near) {
        node = near;
        tmax = near_hi < tmax ? near_hi : tmax;
      } else {
        leaf = false;
        break;
      }
      n = &v.nodes[node];
    }
    if (leaf) intersect_leaf<kCount>(v, *n, ray, wr, hit, nearest, c);
    for (;;) {
      if (sp == 0) return hit;
      const StackEntry& e = stack[--sp];
      if (e.tmin > hit.t) continue;
      node = e.node;
      tmin = e.tmin;
      tmax = e.tmax < hit.t ? e.tmax : hit.t;
      break;
    }
  }
}

/// Depth of the deepest leaf.
int tree_depth(const FlatBspTree& tree) { return flat_bsp_stats(tree).max_depth; }

}  // namespace

BspTracer::BspTracer(FlatBspTree tree, const TriangleSoup& soup, BspEpsilon mode)
    : tree_(std::move(tree)), mode_(mode) {
  try {
    tree_.validate();
  } catch (const std::logic_error& e) {
    throw UsageError(std::string("flat BSP tree is not valid: ") + e.what());
  }
  if (tree_.triangle_count != soup.size())
    throw UsageError("BSP tree built for " + std::to_string(tree_.triangle_count) +
                     " triangles, scene has " + std::to_string(soup.size()));
  if (tree_depth(tree_) >= kBspMaxDepth)
    throw UsageError("BSP tree deeper than " + std::to_string(kBspMaxDepth) + " levels");
  if (mode_ == BspEpsilon::Zero)
    for (std::size_t i = 0; i + 1 < tree_.nodes.size(); ++i)
      if (tree_.nodes[i].is_plane()) tree_.nodes[++i].set_tail_eps(0.0f);
  compact_ = compact_bsp(tree_);
  tree_.nodes = {};  // traversal reads compact_; the leaf lists stay in tree_.prims
  triangles_.resize(tree_.prims.size());
  for (std::size_t i = 0; i < tree_.prims.size(); ++i) {
    const auto c = soup.corners(tree_.prims[i]);
    triangles_[i] = {{c[0], c[1], c[2]}};
  }
}

namespace {
BspView make_view(const FlatBspTree& t, const CompactBspTree& c, const std::vector<BspTriangle>& tris,
                  BspEpsilon mode, const LeafIntersector* exact_leaf) {
  return BspView{c.slots.data(), t.prims.data(), tris.data(), t.bounds, mode == BspEpsilon::Certified,
                 exact_leaf};
}
}  // namespace

Hit BspTracer::trace(const Ray& ray, RayCounters* counters) const {
  const BspView v = make_view(tree_, compact_, triangles_, mode_, exact_leaf_);
  if (tree_.bounds.empty()) {
    if (counters) ++counters->rays;
    return Hit{};
  }
  return counters ? trace_single<true>(v, ray, counters) : trace_single<false>(v, ray, nullptr);
}

void BspTracer::trace_batch(std::span<const Ray> rays, std::span<Hit> hits, int packet_width,
                            RayCounters* counters) const {
  if (hits.size() != rays.size())
    throw UsageError("trace_batch: " + std::to_string(rays.size()) + " rays but " +
                     std::to_string(hits.size()) + " hits");
  const Isa need = isa_for_width(packet_width);  // UsageError for bad widths
  if (int(detected_isa()) < int(need))
    throw UsageError("packets of " + std::to_string(packet_width) + " rays need " +
                     isa_name(need) + ", this CPU has " + isa_name(detected_isa()));
  if (need == Isa::Scalar || tree_.bounds.empty() || exact_leaf_) {  // exact leaves: single rays
    for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = trace(rays[i], counters);
    return;
  }
  const BspView v = make_view(tree_, compact_, triangles_, mode_, exact_leaf_);
  switch (need) {
    case Isa::Sse42:
      detail::bsp_trace_packets_sse42(v, rays.data(), rays.size(), hits.data(), counters);
      break;
    case Isa::Avx2:
      detail::bsp_trace_packets_avx2(v, rays.data(), rays.size(), hits.data(), counters);
      break;
    case Isa::Avx512:
      detail::bsp_trace_packets_avx512(v, rays.data(), rays.size(), hits.data(), counters);
      break;
    case Isa::Scalar: break;
  }
}

std::size_t BspTracer::memory_bytes() const {
  return compact_.slots.size() * sizeof(CompactBspSlot) + tree_.prims.size() * sizeof(std::uint32_t) +
         triangles_.size() * sizeof(BspTriangle);
}

}  // namespace bsprt
