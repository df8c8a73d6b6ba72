/// \file bsp_traverse.cpp
/// Single-ray BSP traversal and the dispatcher of the packet kernels. Compiled
/// with -ffp-contract=off: bsp_packet.inl repeats these steps bit for bit.
#include "traverse/bsp/bsp_traverse.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "bsprt/error.h"
#include "traverse/bsp/bsp_kernel.h"
#include "traverse/exact_double_stage.h"
#include "traverse/simd/cpu_features.h"
#include "traverse/simd/simd.h"
#include "traverse/stack_step.h"
#include "traverse/watertight.h"

namespace bsprt {
namespace {

using detail::BspRayConst;
using detail::BspView;

/// Entries of the box top's stack: three per level of Embree's maxDepth (64).
constexpr int kTopStackSize = 3 * 64 + 4;

/// A far child waiting on the stack with the ray's (conservative) interval.
using detail::StackEntry;

/// Per-ray constants of the leaf test: the watertight shear for float
/// leaves, the double filter's for exact ones (exact_double_stage.h). Only
/// the one the tracer uses is made, once per ray, at the ray's first leaf
/// (`ready`): a random ray reaches 0.4 leaves on average (bunny), and the
/// exact constants cost two divisions and a branchy choice of axes.
struct LeafRay {
  WatertightRay wr;
  detail::ExactRayConst er;
  bool ready = false;
};
inline void leaf_ray_setup(const BspView& v, const Ray& ray, LeafRay& lr) {
  if (v.exact_leaf)
    detail::exact_ray_init(ray, lr.er);
  else
    watertight_init(ray, lr.wr);
  lr.ready = true;
}

/// Tests the triangles of a leaf (ties keep the earlier triangle). With an
/// exact leaf test, `nearest` keeps the exact order and the answer; hit then
/// holds its prim and, as t, the cull bound (cull_bound).
template <bool kCount, bool kAnyHit = false>
inline void intersect_leaf(const BspView& v, const CompactBspSlot& n, const Ray& ray, LeafRay& lr,
                           Hit& hit, NearestHit& nearest, RayCounters* c) {
  const std::uint32_t first = n.prim_offset(), end = first + n.prim_count();
  if constexpr (kCount) ++c->leaf_visits;
  if (!lr.ready) [[unlikely]]
    leaf_ray_setup(v, ray, lr);
  if (v.exact_leaf) {
    detail::exact_leaf_staged<kAnyHit>(*v.exact_leaf, ray, lr.er, v.prims + first, v.triangles + first,
                                       n.prim_count(), nearest, kCount ? c : nullptr);
    hit.prim = nearest.hit.prim;
    hit.t = cull_bound(nearest);
    return;
  }
  if constexpr (kCount) c->triangle_tests += n.prim_count();
  for (std::uint32_t i = first; i < end; ++i) {
    const BspTriangle& t = v.triangles[i];
    intersect_watertight_closest(lr.wr, t.v[0], t.v[1], t.v[2], v.prims[i], hit);
  }
}

/// One inner node, for the interleaved single rays (traverse_subtree inlines
/// the same step with the kind tested once, docs/notes/2026-12-04-bsp-kd-step.md):
/// the near child's upper end and the far child's lower end of the ray
/// interval, and whether near is the second child.
template <bool kCount>
inline bool cut_node(const CompactBspSlot* n, const BspRayConst& rc, float& near_hi, float& far_lo,
                     RayCounters* c) {
  if (n->is_plane()) {
    if constexpr (kCount) ++c->bsp_node_visits;
    const float b = detail::plane_cut<float, detail::Order::PerLane>(n, rc.o, rc.dir, rc.err, near_hi, far_lo,
                                                                     rc.tmin >= 0.0f);
    return b < 0.0f;
  }
  if constexpr (kCount) ++c->kd_node_visits;
  const int k = n->axis();
  detail::kd_cut<float, detail::Order::PerLane>(n->split(), rc.o[k], rc.inv[k], near_hi, far_lo, rc.tmin >= 0.0f);
  return rc.neg[k];
}

/// Front-to-back traversal (pbrt's kd-tree loop with the paper's BSP node
/// step, made conservative) of the subtree at slot `root`, entered with the
/// ray interval [tmin, tmax]. A child is culled when its conservative
/// interval is empty (NaN crossings cull nothing) or when it lists no
/// triangle (not stored, bsp_compact.h); a popped cell is skipped when it
/// starts past the nearest hit. bsp_packet.inl repeats these steps.
template <bool kCount, bool kAnyHit = false, detail::Order kOrder = detail::Order::Ordered>
inline void traverse_subtree(const BspView& v, const BspRayConst& rc, const Ray& ray, LeafRay& lr,
                             std::uint32_t root, float tmin, float tmax, Hit& hit, NearestHit& nearest,
                             RayCounters* c) {
  StackEntry stack[kBspMaxDepth];
  int sp = 0;
  std::uint32_t node = root;
  float best = detail::hit_bound(rc, hit.t);  // hit.t in the traversal's parameter; changes at leaves only
  for (;;) {
    const CompactBspSlot* n = &v.nodes[node];
    bool leaf = true;
    while (!n->is_leaf()) {
      // The first child follows this node; fetch the second while t is computed.
      __builtin_prefetch(&v.nodes[n->second_child()]);
      const std::uint32_t head = n->head, kind = head & 7u;
      float near_hi, far_lo;
      bool flip;
      std::uint32_t first;
      if (kind < 3) {  // kd (cut_node, with the kind tested once)
        if constexpr (kCount) ++c->kd_node_visits;
        detail::kd_cut<float, kOrder>(n->split(), rc.o[kind], rc.inv[kind], near_hi, far_lo);
        flip = rc.neg[kind];
        first = node + 1;
      } else {
        if constexpr (kCount) ++c->bsp_node_visits;
        flip = detail::plane_cut<float, kOrder>(n, rc.o, rc.dir, rc.err, near_hi, far_lo) < 0.0f;
        first = node + 3;
      }
      const std::uint32_t second = head >> CompactBspSlot::kShift;
      const std::uint32_t near = flip ? second : first, far = flip ? first : second;
      // Empty children: the near and far child's bit masks are selected like
      // near and far, then tested against head. The compiler splits the step
      // by flip, so each test is one test-and-branch on a constant mask. Not
      // shifted by flip (a variable shift count costs moves into cl on the
      // base ISA), and not bools extracted from head first (six instructions
      // a step, 3-5 % slower on sponza and conference camera rays;
      // docs/notes/2026-12-06-vertex-ties-and-shadow-rays.md).
      const std::uint32_t near_bit = flip ? CompactBspSlot::kSecondEmpty : CompactBspSlot::kFirstEmpty;
      const std::uint32_t far_bit = flip ? CompactBspSlot::kFirstEmpty : CompactBspSlot::kSecondEmpty;
      const bool near_empty = (head & near_bit) != 0, far_empty = (head & far_bit) != 0;
      // NaN: both. Any-hit walks (shadow rays from scattered surface points)
      // combine the tests without branches: on 50K sponza shadow rays that
      // took 13 mispredicts a ray off (cachegrind) and 5 % of the time, while
      // coherent camera rays ran 3 % slower that way (docs/notes/
      // 2026-12-06-vertex-ties-and-shadow-rays.md).
      bool go_near, go_far;
      if constexpr (kAnyHit) {
        go_near = !(near_hi < tmin) & !near_empty, go_far = !(far_lo > tmax) & !far_empty;
      } else {
        go_near = !(near_hi < tmin) && !near_empty, go_far = !(far_lo > tmax) && !far_empty;
      }
      if (!detail::step_near_far(near, far, go_near, go_far, near_hi, far_lo, node, tmin, tmax, stack, sp)) {
        leaf = false;
        break;
      }
      n = &v.nodes[node];
    }
    if (leaf) {
      intersect_leaf<kCount, kAnyHit>(v, *n, ray, lr, hit, nearest, c);
      if constexpr (kAnyHit) {  // occluded: the first leaf with a hit ends the walk
        if (v.exact_leaf ? nearest.hit.hit() : hit.hit()) return;
      }
      best = detail::hit_bound(rc, hit.t);
    }
    if (!detail::pop_before(stack, sp, best, node, tmin, tmax)) return;
  }
}

/// One ray: counts it, makes its constants, and unless it is invalid or
/// misses the root box hands them to walk(rc, lr, hit, nearest).
template <bool kCount, bool kIncoherent = false, typename Walk>
inline Hit trace_ray(const BspView& v, const Ray& ray, RayCounters* c, Walk&& walk) {
  Hit hit;
  if constexpr (kCount) ++c->rays;
  const BspRayConst rc = detail::bsp_ray_setup<kIncoherent>(ray, v.bounds, v.certified);
  if (!rc.live) return hit;
  LeafRay lr;  // made at the first leaf
  NearestHit nearest;
  if constexpr (kCount) {
    const std::uint64_t before = c->exact_decisions;  // set by an exact leaf test
    walk(rc, lr, hit, nearest);
    c->exact_rays += c->exact_decisions != before;
  } else {
    walk(rc, lr, hit, nearest);
  }
  return v.exact_leaf ? nearest.hit : hit;
}

/// One ray through the whole tree; kAnyHit: stop at the first leaf with a hit
/// (occluded), whose hit is some hit in [tnear, tfar], not necessarily the nearest.
/// kIncoherent: the batch's rays look incoherent (bsp_ray_setup's kByMask).
template <bool kCount, bool kAnyHit = false, bool kIncoherent = false>
Hit trace_single(const BspView& v, const Ray& ray, RayCounters* c) {
  return trace_ray<kCount, kIncoherent>(v, ray, c, [&](const BspRayConst& rc, LeafRay& lr, Hit& hit,
                                          NearestHit& nearest) {
    // A segment that starts at t >= 0 (camera and secondary rays) widens
    // without max and min (detail::Order); the packet kernels choose alike.
    if (rc.tmin >= 0.0f)
      traverse_subtree<kCount, kAnyHit, detail::Order::NonNegative>(v, rc, ray, lr, 0, rc.tmin, rc.tmax, hit,
                                                                    nearest, c);
    else
      traverse_subtree<kCount, kAnyHit>(v, rc, ray, lr, 0, rc.tmin, rc.tmax, hit, nearest, c);
  });
}

/// The box top (bsp_boxtop.h), then the BSP subtrees whose boxes the ray
/// enters, nearest box first. A box is entered with the ray's interval
/// clipped to it by widened slab crossings (monotone, so widening the max/min
/// equals widening each crossing as bsp_ray_setup does); a subtree then runs
/// the certified steps from its root.
template <bool kCount>
inline void walk_top(const BspView& v, const BoxTopNode* nodes, const BspRayConst& rc, const Ray& ray,
                     LeafRay& lr, Hit& hit, NearestHit& nearest, RayCounters* c) {
  using V = simd::vfloat<4>;
  struct Entry {
    std::uint32_t ref;
    float tmin, tmax;
  };
  Entry stack[kTopStackSize];
  int sp = 0;
  Entry cur{0, rc.tmin, rc.tmax};
  // Offsets (in floats) of the entry and exit planes of axis k in a node:
  // lo[k] is at 4k, hi[k] at 12 + 4k; a negative direction swaps them.
  int near_off[3], far_off[3];
  for (int k = 0; k < 3; ++k) {
    near_off[k] = 4 * k + (rc.neg[k] ? 12 : 0);
    far_off[k] = 4 * k + (rc.neg[k] ? 0 : 12);
  }
  static_assert(offsetof(BoxTopNode, hi) == 12 * sizeof(float));
  const float inf = std::numeric_limits<float>::infinity();
  float best = detail::hit_bound(rc, hit.t);  // the nearest hit in the traversal's parameter; changes in subtrees only
  for (;;) {
    if ((cur.ref & BoxTopNode::kSubtree) != 0) {
      traverse_subtree<kCount>(v, rc, ray, lr, cur.ref & ~BoxTopNode::kSubtree, cur.tmin,
                               cur.tmax < best ? cur.tmax : best, hit, nearest, c);
      best = detail::hit_bound(rc, hit.t);
    } else {
      const BoxTopNode& n = nodes[cur.ref];
      if constexpr (kCount) ++c->box_node_visits;
      V enter = simd::splat<4>(-inf), exit = simd::splat<4>(inf);
      const float* box = &n.lo[0][0];
      for (int k = 0; k < 3; ++k) {
        const V e = (simd::load<4>(box + near_off[k]) - rc.o[k]) * rc.inv[k];
        const V x = (simd::load<4>(box + far_off[k]) - rc.o[k]) * rc.inv[k];
        enter = e > enter ? e : enter;  // NaN crossings do not clip
        exit = x < exit ? x : exit;
      }
      const float hi = cur.tmax < best ? cur.tmax : best;
      enter = detail::widen_dn(enter);
      exit = detail::widen_up(exit);
      enter = enter > cur.tmin ? enter : simd::splat<4>(cur.tmin);
      exit = exit < hi ? exit : simd::splat<4>(hi);
      const auto live = (enter <= exit) &
                        (simd::load_int<4>(reinterpret_cast<const std::int32_t*>(n.child)) != -1);
      unsigned bits = simd::movemask<4>(live);
      if (bits != 0) {
        alignas(16) float lo[4], up[4];
        simd::store<4>(lo, enter);
        simd::store<4>(up, exit);
        const int i0 = std::countr_zero(bits);
        bits &= bits - 1;
        Entry a{n.child[i0], lo[i0], up[i0]};
        if (bits == 0) {  // one box: the common case, no ordering
          cur = a;
          continue;
        }
        const int i1 = std::countr_zero(bits);
        bits &= bits - 1;
        Entry b{n.child[i1], lo[i1], up[i1]};
        if (b.tmin < a.tmin) std::swap(a, b);
        if (bits == 0) {
          stack[sp++] = b;
          cur = a;
          continue;
        }
        Entry hits[4] = {a, b};  // three or four boxes: insertion sort, nearest first
        int count = 2;
        while (bits != 0) {
          const int i = std::countr_zero(bits);
          bits &= bits - 1;
          const Entry e{n.child[i], lo[i], up[i]};
          int j = count++;
          for (; j > 0 && hits[j - 1].tmin > e.tmin; --j) hits[j] = hits[j - 1];
          hits[j] = e;
        }
        for (int j = count - 1; j > 0; --j) stack[sp++] = hits[j];
        cur = hits[0];
        continue;
      }
    }
    for (;;) {
      if (sp == 0) return;
      cur = stack[--sp];
      if (!(cur.tmin > best)) break;
    }
  }
}

/// One ray through the box top and the subtrees under it.
template <bool kCount>
Hit trace_top(const BspView& v, const BoxTopNode* nodes, const Ray& ray, RayCounters* c) {
  return trace_ray<kCount>(v, ray, c, [&](const BspRayConst& rc, LeafRay& lr, Hit& hit,
                                          NearestHit& nearest) {
    walk_top<kCount>(v, nodes, rc, ray, lr, hit, nearest, c);
  });
}

/// One ray's state for the BVH8 top's subtree callback (bvh8_kernel.h); the
/// BSP's constants are made at the first subtree the ray enters (most random
/// rays enter none).
struct WideRay {
  /// rc is left unset until set_up (aggregate initialization cleared it for
  /// every ray with a `rep stos`, whose start-up cost shows on short rays).
  WideRay(const BspView* view, const Ray* r, const Bvh8Subtree* s) : v(view), ray(r), subtrees(s) {}
  const BspView* v;
  const Ray* ray;
  const Bvh8Subtree* subtrees;
  bool set_up = false;
  BspRayConst rc;    ///< made at the first subtree the ray enters
  LeafRay lr;        ///< made at the first leaf the ray reaches (intersect_leaf)
};

/// Subtree `index` under the BVH8 top: the ray's interval clipped to the
/// subtree's certified box by widened slab crossings, exactly as walk_top
/// clips (the kernel's own box test proves only that the box is entered, not
/// where), and to the nearest hit so far; then the certified BSP steps.
template <bool kCount>
void wide_subtree(WideRay& w, std::uint32_t index, Hit& hit, NearestHit& nearest, RayCounters* c) {
  if (!w.set_up) w.rc = detail::bsp_ray_setup(*w.ray, w.v->bounds, w.v->certified), w.set_up = true;
  const BspRayConst& rc = w.rc;
  if (!rc.live) return;  // the ray misses the root cell: no subtree can hit
  const Box3f& box = w.subtrees[index].box;
  const float inf = std::numeric_limits<float>::infinity();
  float enter = -inf, exit = inf;
  for (int k = 0; k < 3; ++k) {
    const float lo = (box.lo[k] - rc.o[k]) * rc.inv[k], hi = (box.hi[k] - rc.o[k]) * rc.inv[k];
    const float e = rc.neg[k] ? hi : lo, x = rc.neg[k] ? lo : hi;
    enter = e > enter ? e : enter;  // NaN crossings do not clip
    exit = x < exit ? x : exit;
  }
  Hit local;  // exact leaves: the answer is in nearest; local carries its cull bound
  const bool exact = w.v->exact_leaf != nullptr;
  if (exact) local.t = cull_bound(nearest);
  Hit& h = exact ? local : hit;
  const float best = detail::hit_bound(rc, h.t);
  enter = detail::widen_dn(enter);
  exit = detail::widen_up(exit);
  const float tmin = enter > rc.tmin ? enter : rc.tmin;
  float tmax = exit < rc.tmax ? exit : rc.tmax;
  tmax = tmax < best ? tmax : best;
  if (!(tmin <= tmax)) return;
  traverse_subtree<kCount>(*w.v, rc, *w.ray, w.lr, w.subtrees[index].slot, tmin, tmax, h, nearest, c);
}

void wide_subtree_call(void* ctx, std::uint32_t index, Hit& hit, NearestHit& nearest, RayCounters* c) {
  WideRay& w = *static_cast<WideRay*>(ctx);
  if (c)
    wide_subtree<true>(w, index, hit, nearest, c);
  else
    wide_subtree<false>(w, index, hit, nearest, nullptr);
}

/// Whether the BVH8 kernel can take the ray: |o| <= 2^126, so that p - o
/// stays finite (Bvh8Tracer's own limit). A scaled or unsafe ray
/// (bsp_kernel.h) is fine: the subtree clip and steps run in the BSP's
/// parameter, as in walk_top, and compare hits through hit_bound.
inline bool wide_takes(const Ray& ray) {
  for (int k = 0; k < 3; ++k)
    if (!(std::fabs(ray.org[k]) <= 0x1p126f)) return false;
  return true;
}

/// Bit of CompactBspSlot::kFirstEmpty; kSecondEmpty is the next one.
constexpr unsigned kFirstBit = unsigned(std::countr_zero(CompactBspSlot::kFirstEmpty));
static_assert(CompactBspSlot::kSecondEmpty == CompactBspSlot::kFirstEmpty << 1);

using detail::select_bits;

/// One ray's state in the interleaved kernel: traverse_subtree's locals, kept
/// between steps.
struct Lane {
  BspRayConst rc;
  LeafRay lr;  ///< made at the ray's first leaf: most random rays reach none
  Hit hit;
  NearestHit nearest;  ///< exact leaf tests only; only .hit is set before the ray's first leaf
  const Ray* ray;
  std::size_t index;  ///< slot in hits; kIdle: no ray left for this lane
  std::uint32_t node;
  std::uint32_t pop;  ///< 1: the last node entered neither child
  float tmin, tmax;
  int sp;
  StackEntry stack[kBspMaxDepth];
};
constexpr std::size_t kIdle = ~std::size_t(0);

/// One step of lane L, traverse_subtree's decisions in its order: an inner
/// node, choosing the child without a branch (the next step's loads wait on
/// the choice instead of on a predicted jump, which random rays mispredict);
/// or a leaf (or a node that entered neither child) and the pops after it.
/// True when the ray is done.
inline bool lane_step(const BspView& v, Lane& L) {
  const CompactBspSlot* n = &v.nodes[L.node];
  if (!(n->is_leaf() | (L.pop != 0))) {
    float near_hi, far_lo;
    const std::uint32_t flip = cut_node<false>(n, L.rc, near_hi, far_lo, nullptr) ? 1u : 0u;
    const std::uint32_t head = n->head, first = L.node + n->slots(), second = n->second_child();
    const std::uint32_t near = first ^ ((first ^ second) & (0u - flip)), far = near ^ first ^ second;
    const std::uint32_t near_full = ~(head >> (kFirstBit + flip)) & 1u;
    const std::uint32_t far_full = ~(head >> (kFirstBit + 1u - flip)) & 1u;
    const float tmin = L.tmin, tmax = L.tmax;
    const std::uint32_t go_near = std::uint32_t(!(near_hi < tmin)) & near_full;  // NaN: both
    const std::uint32_t go_far = std::uint32_t(!(far_lo > tmax)) & far_full;
    const float far_min = far_lo > tmin ? far_lo : tmin, near_max = near_hi < tmax ? near_hi : tmax;
    // The stack has a slot more than the deepest inner node's depth (the
    // BspTracer constructor checks the depth), so this write stays inside it.
    L.stack[L.sp] = {far, far_min, tmax};  // kept only when both children are entered
    L.sp += int(go_near & go_far);
    const std::uint32_t keep = 0u - go_near;  // all ones: near is next
    L.node = (near & keep) | (far & ~keep);
    L.tmin = select_bits(keep, tmin, far_min);
    L.tmax = select_bits(keep, near_max, tmax);
    L.pop = (go_near | go_far) ^ 1u;
    return false;
  }
  if (L.pop == 0) {
    if (!L.lr.ready) L.nearest = NearestHit{};  // intersect_leaf makes L.lr
    intersect_leaf<false>(v, *n, *L.ray, L.lr, L.hit, L.nearest, nullptr);
  }
  const float best = detail::hit_bound(L.rc, L.hit.t);
  for (;;) {
    if (L.sp == 0) return true;
    const StackEntry& e = L.stack[--L.sp];
    if (e.tmin > best) continue;
    L.node = e.node;
    L.tmin = e.tmin;
    L.tmax = e.tmax < best ? e.tmax : best;
    L.pop = 0;
    return false;
  }
}

/// Rays in flight in the interleaved kernel (4 and 16 measured no faster).
constexpr int kLanes = 8;

/// Single rays through the whole tree, kLanes at a time in round robin: while
/// one ray's step waits on its loads and arithmetic, the others' run. Each
/// ray makes exactly the steps of trace_single (float leaves, no counters),
/// so its hit is the same bit for bit.
void trace_interleaved(const BspView& v, const Ray* rays, std::size_t count, Hit* hits) {
  Lane lanes[kLanes];
  std::size_t next = 0;
  auto start = [&](Lane& L) {  // the lane's next live ray, or kIdle
    while (next < count) {
      const std::size_t i = next++;
      L.rc = detail::bsp_ray_setup<true>(rays[i], v.bounds, v.certified);  // incoherent rays
      if (!L.rc.live) {
        hits[i] = Hit{};
        continue;
      }
      L.lr.ready = false;
      L.hit = Hit{};
      L.nearest.hit = Hit{};  // the rest at the ray's first leaf (lr.ready): most random rays reach none
      L.ray = &rays[i];
      L.index = i;
      L.node = 0;
      L.pop = 0;
      L.tmin = L.rc.tmin;
      L.tmax = L.rc.tmax;
      L.sp = 0;
      return;
    }
    L.index = kIdle;
  };
  int active = 0;
  for (Lane& L : lanes) {
    start(L);
    active += L.index != kIdle;
  }
  while (active > 0) {
    for (Lane& L : lanes) {
      if (L.index == kIdle || !lane_step(v, L)) continue;
      hits[L.index] = v.exact_leaf ? L.nearest.hit : L.hit;
      start(L);
      active -= L.index == kIdle;
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

namespace {
/// Whether test(i) holds for at least half of up to 16 evenly spaced i in [0, n).
template <typename Test>
bool half_of_samples(std::size_t n, Test test) {
  const std::size_t samples = std::min<std::size_t>(16, n), step = n / samples;
  std::size_t yes = 0;
  for (std::size_t p = 0; p < samples; ++p) yes += test(p * step);
  return 2 * yes >= samples;
}
}  // namespace

namespace {
/// Whether two directions are within about 8 degrees (cos^2 > 0.98). In
/// double: squared lengths and their products of any finite float direction
/// neither overflow nor underflow there. NaN or a zero direction: not close.
bool directions_close(const Vec3f& a, const Vec3f& b) {
  const Vec3d da(a), db(b);
  const double ab = dot(da, db);
  return ab > 0.0 && ab * ab > 0.98 * dot(da, da) * dot(db, db);
}
}  // namespace

bool rays_look_coherent(std::span<const Ray> rays) {
  if (rays.size() < 2) return true;
  return half_of_samples(rays.size() - 1,
                         [&](std::size_t i) { return directions_close(rays[i].dir, rays[i + 1].dir); });
}

bool packet_looks_coherent(std::span<const Ray> rays) {
  // directions_close(first, d) for each valid lane d, its operations in its
  // order (so the same answer), with the first lane's terms made once and each
  // lane's squared length shared with its validity test. Run for every
  // packet: 48 instructions a ray on sponza's camera packets before, 35 now
  // (cachegrind). Two lanes per SSE2 vector measured 37: packing the
  // lanes' directions costs what the vector saves.
  Vec3d first;
  double first98 = 0.0;
  bool have = false;
  for (const Ray& r : rays) {
    const Vec3d d(r.dir);
    const double len2 = dot(d, d);
    // An invalid lane (zero, NaN or infinite direction) traces nothing.
    if (!(len2 > 0.0 && len2 < std::numeric_limits<double>::infinity())) continue;
    if (!have) {
      first = d, first98 = 0.98 * len2, have = true;
      continue;
    }
    const double ab = dot(first, d);
    if (!(ab > 0.0 && ab * ab > first98 * len2)) return false;
  }
  return true;
}

bool rays_unbounded(std::span<const Ray> rays) {
  return !rays.empty() && half_of_samples(rays.size(), [&](std::size_t i) {
    return rays[i].tfar == std::numeric_limits<float>::infinity();
  });
}

Hit BspTracer::trace(const Ray& ray, RayCounters* counters) const {
  const BspView v = make_view(tree_, compact_, triangles_, mode_, exact_leaf_);
  if (tree_.bounds.empty()) {
    if (counters) ++counters->rays;
    return Hit{};
  }
  if (wide_ && wide_safe_scene_ && wide_takes(ray)) {
    WideRay w{&v, &ray, wide_->tree().subtrees.data()};
    return wide_->trace_with(ray, wide_subtree_call, &w, counters);
  }
  if (has_top_) {
    if (top_.nodes.empty()) {
      if (counters) ++counters->rays;
      return Hit{};
    }
    return counters ? trace_top<true>(v, top_.nodes.data(), ray, counters)
                    : trace_top<false>(v, top_.nodes.data(), ray, nullptr);
  }
  return counters ? trace_single<true>(v, ray, counters) : trace_single<false>(v, ray, nullptr);
}

void BspTracer::trace_batch(std::span<const Ray> rays, std::span<Hit> hits, int packet_width,
                            RayCounters* counters) const {
  const Isa need = check_trace_batch(rays.size(), hits.size(), packet_width);
  const BspView v = make_view(tree_, compact_, triangles_, mode_, exact_leaf_);
  // Box tops trace single rays, and so do exact leaves when counted (the
  // packet kernels count no exact decisions; the counts are the same).
  const auto singles = [&](std::span<const Ray> r, std::span<Hit> h) {
    if (interleaves(r, counters != nullptr)) {
      trace_interleaved(v, r.data(), r.size(), h.data());
      return;
    }
    // Incoherent rays in the plain walk (small trees; not counted, no top):
    // the root clip without a branch on the direction's signs.
    if (!counters && !has_top_ && !wide_ && !tree_.bounds.empty() && !rays_look_coherent(r)) {
      for (std::size_t i = 0; i < r.size(); ++i) h[i] = trace_single<false, false, true>(v, r[i], nullptr);
      return;
    }
    for (std::size_t i = 0; i < r.size(); ++i) h[i] = trace(r[i], counters);
  };
  if (need == Isa::Scalar || tree_.bounds.empty() || (exact_leaf_ && counters) || has_top_ || wide_) {
    singles(rays, hits);
    return;
  }
  const auto packets = [&](std::span<const Ray> r, std::span<Hit> h) {
    switch (need) {
      case Isa::Sse42:
        detail::bsp_trace_packets_sse42(v, r.data(), r.size(), h.data(), counters);
        break;
      case Isa::Avx2:
        detail::bsp_trace_packets_avx2(v, r.data(), r.size(), h.data(), counters);
        break;
      case Isa::Avx512:
        detail::bsp_trace_packets_avx512(v, r.data(), r.size(), h.data(), counters);
        break;
      case Isa::Scalar: break;
    }
  };
  if (packets_ == BspPackets::Always) {
    packets(rays, hits);
    return;
  }
  // Runs of coherent packets go to the packet kernel, runs of incoherent ones
  // to the single rays, each run whole (the interleaved kernel keeps eight
  // rays in flight across packet boundaries).
  const std::size_t n = rays.size(), w = std::size_t(packet_width);
  const auto coherent = [&](std::size_t at) { return packet_looks_coherent(rays.subspan(at, std::min(w, n - at))); };
  bool c = coherent(0);  // of the packet at `at`; each packet is tested once
  for (std::size_t at = 0; at < n;) {
    std::size_t end = at + w;
    bool next = c;
    while (end < n && (next = coherent(end)) == c) end += w;
    end = std::min(end, n);
    if (c) packets(rays.subspan(at, end - at), hits.subspan(at, end - at));
    else singles(rays.subspan(at, end - at), hits.subspan(at, end - at));
    at = end, c = next;
  }
}

std::vector<BspSubtreeBox> BspTracer::subtree_boxes(std::uint32_t max_slots, std::uint32_t max_triangles) const {
  return bsp_subtree_boxes(compact_, triangles_, tree_.bounds, max_slots, tree_.prims, max_triangles);
}

bool BspTracer::occluded(const Ray& ray, RayCounters* counters) const {
  if (wide_ && wide_safe_scene_ && !tree_.bounds.empty() && wide_takes(ray)) {
    const BspView v = make_view(tree_, compact_, triangles_, mode_, exact_leaf_);
    WideRay w{&v, &ray, wide_->tree().subtrees.data()};
    return wide_->occluded_with(ray, wide_subtree_call, &w, counters);
  }
  if (has_top_ || tree_.bounds.empty()) return trace(ray, counters).hit();
  const BspView v = make_view(tree_, compact_, triangles_, mode_, exact_leaf_);
  return (counters ? trace_single<true, true>(v, ray, counters) : trace_single<false, true>(v, ray, nullptr)).hit();
}

void BspTracer::set_bvh8_top(Bvh8Tree top) {
  if (!top.over_bsp) throw UsageError("bsp: a BVH8 top must be built over the BSP (Bvh8Tree::over_bsp)");
  for (const Bvh8Subtree& s : top.subtrees)
    if (s.slot >= compact_.slots.size())
      throw UsageError("bsp: BVH8 top names slot " + std::to_string(s.slot) + " of a tree of " +
                       std::to_string(compact_.slots.size()));
  wide_ = std::make_unique<Bvh8Tracer>(std::move(top));
  wide_->set_exact_leaf(exact_leaf_);
  // |p - o| stays finite in the BVH8 kernel for |o| <= 2^64 (safe rays) and corners within 2^126.
  wide_safe_scene_ = true;
  for (int k = 0; k < 3; ++k)
    wide_safe_scene_ = wide_safe_scene_ && std::fabs(tree_.bounds.lo[k]) <= 0x1p126f &&
                       std::fabs(tree_.bounds.hi[k]) <= 0x1p126f;
}

void BspTracer::set_box_top(BoxTop top) {
  top_ = std::move(top);
  has_top_ = true;
}

std::size_t BspTracer::walk_bytes() const {
  return compact_.slots.size() * sizeof(CompactBspSlot) + tree_.prims.size() * sizeof(std::uint32_t) +
         triangles_.size() * sizeof(BspTriangle);
}

bool BspTracer::interleaves(std::span<const Ray> rays, bool counted) const {
  if (counted || has_top_ || wide_ || tree_.bounds.empty()) return false;
  if (single_rays_ == BspSingleRays::Interleaved) return true;
  return single_rays_ == BspSingleRays::Auto && walk_bytes() >= kInterleaveMinBytes && !rays_look_coherent(rays) &&
         rays_unbounded(rays);
}

std::size_t BspTracer::memory_bytes() const {
  return (wide_ ? wide_->memory_bytes() : 0) + top_.nodes.size() * sizeof(BoxTopNode) + walk_bytes();
}

}  // namespace bsprt
