/// \file bvh8_kernel.inl
/// The BVH8 single-ray kernel, one source compiled per ISA (bvh8_kernel_avx2.cpp,
/// bvh8_kernel_base.cpp; STYLE.md point 13). Define BSPRT_BVH8_ENTRY to the
/// entry point's name before including it.
///
/// The techniques of Embree's single-ray box traversal (Embree 3.13,
/// kernels/bvh/node_intersector1.h, bvh_traverser1.h), written for our node:
/// - per ray, the near and far row of each axis chosen once from the signs of
///   the direction, so no node test branches on it;
/// - per node, (p - o) * r for the six rows (no FMA: its single rounding would
///   break the bound below), min/max folding in tnear and tfar, one compare
///   and a movemask;
/// - child order by the entry distance: one hit child is entered at once, two
///   are ordered by one compare, more get keys (distance bits with the low 3
///   bits cleared) | slot, sorted; the far ones go on the stack, far first;
/// - stack entries (reference, entry distance), dropped on pop when the
///   distance is past the nearest hit.
///
/// Robustness (docs/bvh8.md, "Why no hit is lost"): the reciprocals rn, rf
/// bracket 1/d (bvh8_kernel.h), so the exact products a * rn and a * rf of the
/// rounded differences a = fl(p - o) bracket the exact slab crossings, and
/// rounding to nearest is monotonic: whenever the exact ray meets a box at
/// some t in [tnear, tfar], the computed entry is at most the computed exit.
/// For tnear >= 0 the near rows need only rn and the far rows only rf; a ray
/// with tnear < 0 (kLine) takes the min and max of both products.

#include <bit>
#include <cstdint>
#include <limits>
#include <span>

#include "traverse/bvh/bvh8_kernel.h"
#include "traverse/simd/simd.h"
#include "traverse/watertight.h"

#ifndef BSPRT_BVH8_ENTRY
#error "define BSPRT_BVH8_ENTRY before including bvh8_kernel.inl"
#endif

namespace bsprt::detail {
inline namespace BSPRT_ISA_NAMESPACE {
namespace {

using V = simd::vfloat<8>;

struct Entry {
  std::uint32_t ref;
  float dist;  ///< the child's computed entry t
};

/// Broadcast per-ray constants and the row of each axis's near and far plane.
struct RayConst {
  V o[3], rn[3], rf[3];
  int near_row[3], far_row[3];
};

inline V row(const Bvh8Node& n, int r) { return *reinterpret_cast<const V*>(n.box[r]); }

/// The conservative slab test of the eight children; `dist` gets the entry t
/// of each. Bit i of the result is set when child i may hold a point of the
/// ray in [tnear, tfar]. NaN (0 * inf from d = 0 on a box plane) drops out of
/// the max/min as "no constraint" (operand order matters).
template <bool kLine>
[[gnu::always_inline]] inline unsigned box_test(const Bvh8Node& n, const RayConst& rc, float tnear, float tfar,
                                                V& dist) {
  V tn = simd::splat<8>(tnear), tf = simd::splat<8>(tfar);
  for (int k = 0; k < 3; ++k) {
    const V an = row(n, rc.near_row[k]) - rc.o[k];
    const V af = row(n, rc.far_row[k]) - rc.o[k];
    V nk, fk;
    if constexpr (kLine) {
      nk = simd::min<8>(an * rc.rn[k], an * rc.rf[k]);
      fk = simd::max<8>(af * rc.rn[k], af * rc.rf[k]);
    } else {
      nk = an * rc.rn[k];
      fk = af * rc.rf[k];
    }
    tn = simd::max<8>(nk, tn);
    tf = simd::min<8>(fk, tf);
  }
  dist = tn;
  return simd::movemask<8>(tn <= tf);
}

/// Sort key: distance bits in an order that sorts like the floats (negative
/// distances only for kLine), low 3 bits replaced by the slot.
inline std::uint32_t key(float d, unsigned slot) {
  std::uint32_t b = std::bit_cast<std::uint32_t>(d);
  b ^= (b >> 31) ? 0xffffffffu : 0x80000000u;
  return (b & ~7u) | slot;
}

inline void prefetch_node(const Bvh8View& v, std::uint32_t ref) {
  if (Bvh8Node::is_leaf(ref)) return;
  const char* p = reinterpret_cast<const char*>(&v.nodes[Bvh8Node::index(ref)]);
  __builtin_prefetch(p);
  __builtin_prefetch(p + 64);
  __builtin_prefetch(p + 128);
  __builtin_prefetch(p + 192);
}

template <bool kCount, bool kLine>
Hit trace_kernel(const Bvh8View& v, const Ray& ray, RayCounters* c) {
  const Bvh8RayRecip rr = bvh8_reciprocals(ray);
  // The watertight shear, made at the first leaf: most random rays reach none.
  WatertightRay wr;
  bool sheared = false;
  RayConst rc;
  for (int k = 0; k < 3; ++k) {
    rc.o[k] = simd::splat<8>(ray.org[k]);
    rc.rn[k] = simd::splat<8>(rr.rn[k]);
    rc.rf[k] = simd::splat<8>(rr.rf[k]);
    const bool neg = std::signbit(rr.rf[k]);
    rc.near_row[k] = 2 * k + (neg ? 1 : 0);
    rc.far_row[k] = 2 * k + (neg ? 0 : 1);
  }
  // tnear + 0 turns -0 into +0 (the key order); a hit is finite, so an exit
  // past FLT_MAX is no exit, which keeps rays with d = 0 out of slabs they lie beside.
  const float tnear = ray.tnear + 0.0f;
  float tfar = ray.tfar < std::numeric_limits<float>::max() ? ray.tfar : std::numeric_limits<float>::max();

  Hit hit;
  NearestHit nearest;
  Entry stack[kBvh8StackSize];
  int sp = 0;
  std::uint32_t ref = Bvh8Node::inner_ref(0);
  alignas(32) float dist[8];
  for (;;) {
    while (!Bvh8Node::is_leaf(ref)) {
      const Bvh8Node& n = v.nodes[Bvh8Node::index(ref)];
      if constexpr (kCount) ++c->box_node_visits;
      V d;
      unsigned m = box_test<kLine>(n, rc, tnear, tfar, d);
      if (m == 0) goto pop;
      *reinterpret_cast<V*>(dist) = d;
      const unsigned s0 = unsigned(__builtin_ctz(m));
      m &= m - 1;
      if (m == 0) {
        ref = n.child[s0];
        continue;
      }
      const unsigned s1 = unsigned(__builtin_ctz(m));
      m &= m - 1;
      if (m == 0) {
        const bool first = dist[s0] <= dist[s1];
        const unsigned nearer = first ? s0 : s1, farther = first ? s1 : s0;
        stack[sp++] = {n.child[farther], dist[farther]};
        ref = n.child[nearer];
        prefetch_node(v, ref);
        continue;
      }
      std::uint32_t keys[8];
      int count = 0;
      keys[count++] = key(dist[s0], s0);
      keys[count++] = key(dist[s1], s1);
      while (m) {
        const unsigned s = unsigned(__builtin_ctz(m));
        m &= m - 1;
        keys[count++] = key(dist[s], s);
      }
      for (int i = 1; i < count; ++i) {  // insertion sort, descending: at most 8 keys
        const std::uint32_t x = keys[i];
        int j = i;
        for (; j > 0 && keys[j - 1] < x; --j) keys[j] = keys[j - 1];
        keys[j] = x;
      }
      for (int i = 0; i + 1 < count; ++i) {
        const unsigned s = keys[i] & 7u;
        stack[sp++] = {n.child[s], dist[s]};
      }
      ref = n.child[keys[count - 1] & 7u];
      prefetch_node(v, ref);
    }
    {  // a leaf
      const std::uint32_t first = Bvh8Node::index(ref), count = Bvh8Node::count(ref);
      if constexpr (kCount) ++c->leaf_visits;
      if (v.exact_leaf) {
        v.exact_leaf->intersect(ray, std::span<const std::uint32_t>(v.prims + first, count), v.triangles + first,
                                nearest, kCount ? c : nullptr);
        const float cull = cull_bound(nearest);
        tfar = cull < tfar ? cull : tfar;
      } else {
        if constexpr (kCount) c->triangle_tests += count;
        if (!sheared) wr = watertight_precompute(ray), sheared = true;
        for (std::uint32_t i = first; i < first + count; ++i) {
          const LeafTriangle& t = v.triangles[i];
          intersect_watertight_closest(wr, t.v[0], t.v[1], t.v[2], v.prims[i], hit);
        }
        tfar = hit.t < tfar ? hit.t : tfar;
      }
    }
  pop:
    for (;;) {
      if (sp == 0) return v.exact_leaf ? nearest.hit : hit;
      const Entry e = stack[--sp];
      if (e.dist <= tfar) {
        ref = e.ref;
        break;
      }
    }
  }
}

template <bool kCount>
Hit trace_counted(const Bvh8View& v, const Ray& ray, RayCounters* c) {
  if constexpr (kCount) ++c->rays;
  if (!is_valid(ray)) return Hit{};
  const auto walk = [&] {
    return ray.tnear >= 0.0f ? trace_kernel<kCount, false>(v, ray, c) : trace_kernel<kCount, true>(v, ray, c);
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

}  // namespace
}  // namespace BSPRT_ISA_NAMESPACE

Hit BSPRT_BVH8_ENTRY(const Bvh8View& view, const Ray& ray, RayCounters* c) {
  return c ? trace_counted<true>(view, ray, c) : trace_counted<false>(view, ray, nullptr);
}

}  // namespace bsprt::detail
