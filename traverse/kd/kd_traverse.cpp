/// \file kd_traverse.cpp
/// Single-ray kd traversal and the dispatcher of the packet kernels.
#include "traverse/kd/kd_traverse.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "bsprt/error.h"
#include "traverse/simd/cpu_features.h"
#include "traverse/kd/kd_kernel.h"
#include "traverse/stack_step.h"
#include "traverse/watertight.h"

namespace bsprt {
namespace {

using detail::KdView;
using detail::kKdTHi;
using detail::kKdTLo;

/// A far child waiting on the stack with the ray's (widened) interval in it.
using detail::StackEntry;

/// Clips [tmin, tmax] to the root cell, with the same widening as the nodes.
/// A zero direction component gives inv = +-inf: outside the slab both t are
/// the same infinity (empty), inside they are -inf/+inf (no constraint), on
/// the slab's plane 0 * inf = NaN, which the selects ignore. A subnormal
/// component gives inv = NaN (detail::kd_reciprocal), as does an origin so far
/// out that (b - o) could overflow: that slab does not clip.
inline void clip_root(const Box3f& b, const float o[3], const float inv[3], const bool neg[3],
                      float& tmin, float& tmax) {
  for (int k = 0; k < 3; ++k) {
    const float t0 = (b.lo[k] - o[k]) * inv[k], t1 = (b.hi[k] - o[k]) * inv[k];
    const float tn = neg[k] ? t1 : t0, tf = neg[k] ? t0 : t1;
    const float na = tn * kKdTLo, nb = tn * kKdTHi, fa = tf * kKdTLo, fb = tf * kKdTHi;
    const float enter = na < nb ? na : nb, exit = fa > fb ? fa : fb;
    tmin = enter > tmin ? enter : tmin;
    tmax = exit < tmax ? exit : tmax;
  }
}

/// Tests the triangles of a leaf. With an exact leaf test, `nearest` keeps the
/// exact order and the answer; hit then holds its prim and, as t, the cull
/// bound (cull_bound).
template <bool kCount, bool kAnyHit = false>
inline void intersect_leaf(const KdView& v, const KdNode& n, const Ray& ray, const WatertightRay& wr, bool filter,
                           Hit& hit, detail::LazyExactRay& er, NearestHit& nearest, RayCounters* c) {
  const std::uint32_t first = n.prim_offset(), end = first + n.prim_count();
  if (v.exact_leaf) {
    if constexpr (kCount) ++c->leaf_visits;
    // An empty leaf (most leaves a ray visits in the shared scenes) leaves
    // `nearest`, and so `hit`, as they are: no call.
    if (first == end) return;
    detail::kd_exact_leaf<kAnyHit>(v, first, end, ray, wr, filter, er, nearest, kCount ? c : nullptr);
    hit.prim = nearest.hit.prim;
    hit.t = cull_bound(nearest);
    return;
  }
  if constexpr (kCount) {
    ++c->leaf_visits;
    c->triangle_tests += n.prim_count();
  }
  for (std::uint32_t i = first; i < end; ++i) {
    const std::uint32_t p = v.prims[i];
    const KdTriangle& t = v.triangles[p];
    intersect_watertight_closest(wr, t.v[0], t.v[1], t.v[2], p, hit);
  }
}

/// Front-to-back traversal (pbrt's KdTreeAggregate::Intersect, made
/// conservative). Near/far come from the sign of the direction, so the order
/// is right for any tnear; a child is culled only when its widened interval is
/// empty (NaN from a ray in the plane: both). Branches, not selects: predicted
/// branches let the CPU fetch the next node before t is known (a branch-free
/// step measured 30% slower). A popped cell is skipped when its entry is past
/// the nearest hit. kd_packet.inl repeats these steps lane by lane, bit for bit.
/// `filter`: exact leaves may use their float prefilter (detail::filterable,
/// a property of the ray, made once per ray). kAnyHit: stop after the first
/// leaf that yields a hit (occluded); the hit is then some hit in
/// [tnear, tfar], not necessarily the nearest.
template <bool kCount, bool kNonNegative, bool kAnyHit = false>
Hit trace_from(const KdView& v, const Ray& ray, const WatertightRay& wr, bool filter, const float o[3],
               const float inv[3], const bool neg[3], float tmin, float tmax, RayCounters* c) {
  Hit hit;
  NearestHit nearest;
  detail::LazyExactRay er;  // exact leaves: the ray's double constants, made on first use
  StackEntry stack[kKdMaxDepth];
  int sp = 0;
  std::uint32_t node = 0;
  for (;;) {
    const KdNode* n = &v.nodes[node];
    while (!n->is_leaf()) {
      __builtin_prefetch(&v.nodes[n->upper_child()]);  // lines away (lower follows): fetch it while t is computed
      if constexpr (kCount) ++c->kd_node_visits;
      const int k = n->axis();
      const float t = (n->split - o[k]) * inv[k];
      const float ta = t * kKdTLo, tb = t * kKdTHi;
      float tl, th;
      if constexpr (kNonNegative) {
        // tmin >= 0: for t < 0 the unordered pair decides exactly as the
        // ordered one (both say: far only, from tmin), so skip the min/max.
        tl = ta, th = tb;
      } else {
        tl = ta < tb ? ta : tb, th = ta > tb ? ta : tb;
      }
      const std::uint32_t lower = node + 1, upper = n->upper_child();
      const std::uint32_t near = neg[k] ? upper : lower, far = neg[k] ? lower : upper;
      const bool go_near = !(th < tmin), go_far = !(tl > tmax);  // NaN: both
      // Neither: cannot happen (th >= tl, NaN visits both), kept for safety.
      if (!detail::step_near_far(near, far, go_near, go_far, th, tl, node, tmin, tmax, stack, sp)) break;
      n = &v.nodes[node];
    }
    if (n->is_leaf()) {
      intersect_leaf<kCount, kAnyHit>(v, *n, ray, wr, filter, hit, er, nearest, c);
      if constexpr (kAnyHit) {
        if (v.exact_leaf ? nearest.hit.hit() : hit.hit()) return v.exact_leaf ? nearest.hit : hit;
      }
    }
    if (!detail::pop_before(stack, sp, hit.t, node, tmin, tmax)) return v.exact_leaf ? nearest.hit : hit;
  }
}

template <bool kCount, bool kAnyHit = false>
Hit trace_single(const KdView& v, const Ray& ray, RayCounters* c) {
  Hit hit;
  if constexpr (kCount) ++c->rays;
  const WatertightRay wr = watertight_precompute(ray);
  if (!wr.valid) return hit;
  const float o[3] = {ray.org.x, ray.org.y, ray.org.z};
  const float inv[3] = {detail::kd_reciprocal(ray.dir.x, o[0], detail::kd_reach(v.bounds, 0)),
                        detail::kd_reciprocal(ray.dir.y, o[1], detail::kd_reach(v.bounds, 1)),
                        detail::kd_reciprocal(ray.dir.z, o[2], detail::kd_reach(v.bounds, 2))};
  const bool neg[3] = {std::signbit(ray.dir.x), std::signbit(ray.dir.y), std::signbit(ray.dir.z)};
  float tmin = ray.tnear, tmax = ray.tfar;
  clip_root(v.bounds, o, inv, neg, tmin, tmax);
  if (!(tmin <= tmax)) return hit;
  const bool filter = v.exact_leaf && detail::filterable(wr, ray);
  const auto walk = [&]() {
    return tmin >= 0.0f ? trace_from<kCount, true, kAnyHit>(v, ray, wr, filter, o, inv, neg, tmin, tmax, c)
                        : trace_from<kCount, false, kAnyHit>(v, ray, wr, filter, o, inv, neg, tmin, tmax, c);
  };
  if constexpr (kCount) {
    const std::uint64_t before = c->exact_decisions;  // set by an exact leaf test
    const Hit h = walk();
    c->exact_rays += c->exact_decisions != before;
    return h;
  } else {
    return walk();
  }
}

Hit trace_single_counted(const KdView& v, const Ray& ray, RayCounters* c) {
  return c ? trace_single<true>(v, ray, c) : trace_single<false>(v, ray, nullptr);
}

int tree_depth(const KdTree& tree) { return kd_tree_stats(tree).max_depth; }

}  // namespace

KdTracer::KdTracer(KdTree tree, const TriangleSoup& soup) : tree_(std::move(tree)) {
  try {
    tree_.validate();
  } catch (const std::logic_error& e) {
    throw UsageError(std::string("kd-tree is not valid: ") + e.what());
  }
  if (tree_.triangle_count != soup.size())
    throw UsageError("kd-tree built for " + std::to_string(tree_.triangle_count) +
                     " triangles, scene has " + std::to_string(soup.size()));
  if (tree_depth(tree_) >= kKdMaxDepth)
    throw UsageError("kd-tree deeper than " + std::to_string(kKdMaxDepth) + " levels");
  triangles_.resize(soup.size());
  for (std::uint32_t i = 0; i < soup.size(); ++i) {
    const auto c = soup.corners(i);
    triangles_[i] = {{c[0], c[1], c[2]}};
  }
}

Hit KdTracer::trace(const Ray& ray, RayCounters* counters) const {
  const KdView v{tree_.nodes.data(), tree_.prims.data(), triangles_.data(), tree_.bounds, exact_leaf_};
  return counters ? trace_single<true>(v, ray, counters) : trace_single<false>(v, ray, nullptr);
}

bool KdTracer::occluded(const Ray& ray, RayCounters* counters) const {
  const KdView v{tree_.nodes.data(), tree_.prims.data(), triangles_.data(), tree_.bounds, exact_leaf_};
  return (counters ? trace_single<true, true>(v, ray, counters) : trace_single<false, true>(v, ray, nullptr)).hit();
}

void KdTracer::trace_batch(std::span<const Ray> rays, std::span<Hit> hits, int packet_width,
                           RayCounters* counters) const {
  const Isa need = check_trace_batch(rays.size(), hits.size(), packet_width);
  const KdView v{tree_.nodes.data(), tree_.prims.data(), triangles_.data(), tree_.bounds, exact_leaf_};
  // Exact leaves when counted: single rays (the packet kernels count no exact
  // decisions; the counts are the same).
  switch (exact_leaf_ && counters ? Isa::Scalar : need) {
    case Isa::Scalar:
      for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = trace_single_counted(v, rays[i], counters);
      break;
    case Isa::Sse42:
      detail::kd_trace_packets_sse42(v, rays.data(), rays.size(), hits.data(), counters, trace_single_counted);
      break;
    case Isa::Avx2:
      detail::kd_trace_packets_avx2(v, rays.data(), rays.size(), hits.data(), counters, trace_single_counted);
      break;
    case Isa::Avx512:
      detail::kd_trace_packets_avx512(v, rays.data(), rays.size(), hits.data(), counters, trace_single_counted);
      break;
  }
}

std::size_t KdTracer::memory_bytes() const {
  return tree_.memory_bytes() + triangles_.size() * sizeof(KdTriangle);
}

}  // namespace bsprt
