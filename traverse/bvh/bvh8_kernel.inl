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
#include "traverse/exact_double_stage.h"
#include "traverse/exact_prefilter.h"
#include "traverse/simd/simd.h"
#include "traverse/simd/watertight_packet.h"
#include "traverse/watertight.h"

#if !defined(BSPRT_BVH8_ENTRY) || !defined(BSPRT_BVH8_OCCLUDED) || !defined(BSPRT_BVH8_BATCH)
#error "define BSPRT_BVH8_ENTRY, BSPRT_BVH8_OCCLUDED and BSPRT_BVH8_BATCH before including bvh8_kernel.inl"
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

/// Lane i of v, without a round trip through memory where the ISA has a
/// variable permute (a store and a narrower reload can stall forwarding).
[[gnu::always_inline]] inline float lane_of(V v, unsigned i) {
#if defined(__AVX2__)
  return _mm256_cvtss_f32(_mm256_permutevar8x32_ps(reinterpret_cast<__m256>(v), _mm256_set1_epi32(int(i))));
#else
  return v[i];
#endif
}

/// Sort key: distance bits in an order that sorts like the floats (negative
/// distances only for kLine), low 3 bits replaced by the slot.
inline std::uint32_t key(float d, unsigned slot) {
  std::uint32_t b = std::bit_cast<std::uint32_t>(d);
  b ^= (b >> 31) ? 0xffffffffu : 0x80000000u;
  return (b & ~7u) | slot;
}

/// Prefetches what a reference points to: a node's four lines, or a leaf's
/// first corners (Embree prefetches every hit child the same way); nothing
/// for a BSP subtree (kSubtrees), whose first node the callback finds.
template <bool kSubtrees>
inline void prefetch_ref(const Bvh8View& v, std::uint32_t ref) {
  if (Bvh8Node::is_leaf(ref)) {
    if (kSubtrees && Bvh8Node::count(ref) == Bvh8Node::kSubtree) return;
    const char* p = reinterpret_cast<const char*>(v.leaf_soa + Bvh8Tree::kSoaFloats * std::size_t(Bvh8Node::index(ref)));
    __builtin_prefetch(p);
    __builtin_prefetch(p + 64);
    if (Bvh8Node::count(ref) > 1) __builtin_prefetch(p + 128);
    return;
  }
  const char* p = reinterpret_cast<const char*>(&v.nodes[Bvh8Node::index(ref)]);
  __builtin_prefetch(p);
  __builtin_prefetch(p + 64);
  __builtin_prefetch(p + 128);
  __builtin_prefetch(p + 192);
}

/// Orders a, b so that a >= b, without a branch.
[[gnu::always_inline]] inline void sort_pair_desc(std::uint32_t& a, std::uint32_t& b) {
  const std::uint32_t hi = a > b ? a : b, lo = a > b ? b : a;
  a = hi, b = lo;
}

/// Sorts keys[0..n) descending: networks for 3 and 4 (the common cases),
/// insertion sort beyond.
inline void sort_keys_desc(std::uint32_t* k, int n) {
  if (n == 3) {
    sort_pair_desc(k[0], k[1]);
    sort_pair_desc(k[1], k[2]);
    sort_pair_desc(k[0], k[1]);
    return;
  }
  if (n == 4) {
    sort_pair_desc(k[0], k[1]);
    sort_pair_desc(k[2], k[3]);
    sort_pair_desc(k[0], k[2]);
    sort_pair_desc(k[1], k[3]);
    sort_pair_desc(k[1], k[2]);
    return;
  }
  for (int i = 1; i < n; ++i) {
    const std::uint32_t x = k[i];
    int j = i;
    for (; j > 0 && k[j - 1] < x; --j) k[j] = k[j - 1];
    k[j] = x;
  }
}

/// The watertight test (watertight.h) of one ray against the `count` (1..4)
/// triangles of a leaf at once, SoA rows at `rows` (bvh8_node.h, the tenth
/// row holding the triangle numbers): lane by lane the same IEEE operations in the same
/// order, lanes with an exactly zero edge function redone by the same double
/// fallback, so the result is the scalar leaf loop's bit for bit: the
/// smallest t in [tnear, tfar] below hit.t, the earliest lane among equal t.
inline void intersect_leaf(const WatertightRay& r, const float* rows, std::uint32_t count, Hit& hit) {
  using V4 = simd::vfloat<4>;
  using M4 = simd::vmask<4>;
  const auto lane = [&](int c, int k) { return simd::load<4>(rows + (3 * c + k) * count); };
  V4 rel[3][3];  // corner c minus the origin, axis k
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) rel[c][k] = lane(c, k) - r.org[k];
  const V4 sx = simd::splat<4>(r.sx), sy = simd::splat<4>(r.sy), sz = simd::splat<4>(r.sz);
  const V4 az = rel[0][r.kz], bz = rel[1][r.kz], cz = rel[2][r.kz];
  const V4 ax = rel[0][r.kx] - no_fma(sx * az), ay = rel[0][r.ky] - no_fma(sy * az);
  const V4 bx = rel[1][r.kx] - no_fma(sx * bz), by = rel[1][r.ky] - no_fma(sy * bz);
  const V4 cx = rel[2][r.kx] - no_fma(sx * cz), cy = rel[2][r.ky] - no_fma(sy * cz);
  V4 u = no_fma(cx * by) - no_fma(cy * bx);
  V4 v = no_fma(ax * cy) - no_fma(ay * cx);
  V4 w = no_fma(bx * ay) - no_fma(by * ax);
  const M4 live = simd::VecTypes<4>::I{0, 1, 2, 3} < std::int32_t(count);
  const M4 zero = ((u == 0.0f) | (v == 0.0f) | (w == 0.0f)) & live;
  if (simd::any<4>(zero)) simd::watertight_detail::edges_double_lanes<4>(zero, ax, ay, bx, by, cx, cy, u, v, w);
  const M4 neg = (u < 0.0f) | (v < 0.0f) | (w < 0.0f), pos = (u > 0.0f) | (v > 0.0f) | (w > 0.0f);
  // A leaf the ray passes beside (every live lane with edge functions of both
  // signs) ends here, before the determinant and the division, as Embree's
  // leaf tests end on an empty mask.
  const M4 inside = live & ~(neg & pos);
  if (!simd::any<4>(inside)) return;
  const V4 det = u + v + w;
  const V4 tz = no_fma(u * (sz * az)) + no_fma(v * (sz * bz)) + no_fma(w * (sz * cz));
  const V4 t = tz / det;
  const M4 ok = inside & (det != 0.0f) & (t >= r.tnear) & (t <= r.tfar) &
                (t < std::numeric_limits<float>::infinity()) & (t < hit.t);
  unsigned m = simd::movemask<4>(ok);
  if (m == 0) return;
  int best = __builtin_ctz(m);
  for (m &= m - 1; m; m &= m - 1) {
    const int i = __builtin_ctz(m);
    if (t[i] < t[best]) best = i;
  }
  const float rcp = 1.0f / det[best];
  hit.t = t[best];
  hit.prim = Bvh8Tree::decode_prim(rows[9 * count + unsigned(best)]);
  hit.u = v[best] * rcp;
  hit.v = w[best] * rcp;
}

/// kAnyHit: stop at the first hit (occluded); the traversal up to it is the
/// nearest-hit one. kSubtrees: a tree over a BSP, whose kSubtree leaves go to
/// v.subtree (a separate instance, so the plain tree's leaf step is unchanged).
template <bool kCount, bool kLine, bool kAnyHit, bool kSubtrees>
Hit trace_kernel(const Bvh8View& v, const Ray& ray, RayCounters* c) {
  const Bvh8RayRecip rr = bvh8_reciprocals(ray);
  // The watertight shear, made at the first leaf: most random rays reach none.
  WatertightRay wr;
  bool sheared = false, filter = false;
  LazyExactRay er;  // the exact leaves' double constants, likewise
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
      const unsigned s0 = unsigned(__builtin_ctz(m));
      m &= m - 1;
      if (m == 0) {
        ref = n.child[s0];
        prefetch_ref<kSubtrees>(v, ref);
        continue;
      }
      const unsigned s1 = unsigned(__builtin_ctz(m));
      m &= m - 1;
      if (m == 0) {
        const float d0 = lane_of(d, s0), d1 = lane_of(d, s1);
        const bool first = d0 <= d1;
        prefetch_ref<kSubtrees>(v, n.child[s0]);
        prefetch_ref<kSubtrees>(v, n.child[s1]);
        stack[sp++] = {n.child[first ? s1 : s0], first ? d1 : d0};
        ref = n.child[first ? s0 : s1];
        continue;
      }
      *reinterpret_cast<V*>(dist) = d;
      std::uint32_t keys[8];
      int count = 0;
      keys[count++] = key(dist[s0], s0);
      keys[count++] = key(dist[s1], s1);
      while (m) {
        const unsigned s = unsigned(__builtin_ctz(m));
        m &= m - 1;
        keys[count++] = key(dist[s], s);
      }
      sort_keys_desc(keys, count);
      for (int i = 0; i + 1 < count; ++i) {
        const unsigned s = keys[i] & 7u;
        prefetch_ref<kSubtrees>(v, n.child[s]);
        stack[sp++] = {n.child[s], dist[s]};
      }
      ref = n.child[keys[count - 1] & 7u];
      prefetch_ref<kSubtrees>(v, ref);
    }
    {  // a leaf
      const std::uint32_t first = Bvh8Node::index(ref), count = Bvh8Node::count(ref);
      if (kSubtrees && count == Bvh8Node::kSubtree) {
        v.subtree(v.subtree_ctx, first, hit, nearest, kCount ? c : nullptr);
        if (v.exact_leaf) {
          if (kAnyHit && nearest.hit.hit()) return nearest.hit;
          const float cull = cull_bound(nearest);
          tfar = cull < tfar ? cull : tfar;
        } else {
          if (kAnyHit && hit.hit()) return hit;
          tfar = hit.t < tfar ? hit.t : tfar;
        }
        goto pop;
      }
      if constexpr (kCount) ++c->leaf_visits;
      if (v.exact_leaf) {
        // Triangles the float filter proves missed never reach the exact test.
        if (!sheared) watertight_init(ray, wr), sheared = true, filter = filterable(wr, ray);
        const float* rows = v.leaf_soa + Bvh8Tree::kSoaFloats * std::size_t(first);
        const unsigned all = (1u << count) - 1u;
        const unsigned lanes = filter ? exact_lanes(wr, rows, count) : all;
        if (lanes == all) {
          exact_leaf_staged<kAnyHit>(*v.exact_leaf, ray, er.get(ray), v.prims + first, v.triangles + first, count,
                                     nearest, kCount ? c : nullptr);
        } else if (lanes != 0 && v.exact_leaf->staged() && exact_filter_off_for_testing == 0) {
          // Some left out: the others' corners come from the SoA rows the
          // filter has just read, not from the triangle list, another cache
          // line, which random rays miss (500K random bunny rays: 0.109 s ->
          // 0.097 s). A leaf whose every lane survives still reads the list:
          // camera rays have it in cache, and gathering all lanes made them
          // 4-9 % slower (docs/notes/2026-12-07-exact-leaf-rows.md).
          const ExactRayConst& fr = er.get(ray);
          std::uint64_t tests = 0, rules = 0;
          for (unsigned m = lanes; m; m &= m - 1) {
            const unsigned i = unsigned(__builtin_ctz(m));
            std::array<float, 9> tri;
            for (std::uint32_t j = 0; j < 9; ++j) tri[j] = rows[j * count + i];
            exact_one_staged<kAnyHit>(*v.exact_leaf, ray, fr, v.prims[first + i], tri, nearest, kCount ? c : nullptr,
                                      tests, rules);
          }
          if constexpr (kCount) c->triangle_tests += tests, c->rule_decisions += rules;
        } else if (lanes != 0) {  // the intersector itself, on the survivors as a list
          std::uint32_t p[4];
          LeafTriangle t[4];
          std::uint32_t n = 0;
          for (unsigned m = lanes; m; m &= m - 1, ++n) {
            const unsigned i = unsigned(__builtin_ctz(m));
            p[n] = v.prims[first + i];
            t[n] = v.triangles[first + i];
          }
          exact_leaf_staged<kAnyHit>(*v.exact_leaf, ray, er.get(ray), p, t, n, nearest, kCount ? c : nullptr);
        }
        if constexpr (kCount) c->triangle_tests += count - std::uint32_t(__builtin_popcount(lanes));
        if (kAnyHit && nearest.hit.hit()) return nearest.hit;
        const float cull = cull_bound(nearest);
        tfar = cull < tfar ? cull : tfar;
      } else {
        if constexpr (kCount) c->triangle_tests += count;
        if (!sheared) watertight_init(ray, wr), sheared = true;
        intersect_leaf(wr, v.leaf_soa + Bvh8Tree::kSoaFloats * std::size_t(first), count, hit);
        if (kAnyHit && hit.hit()) return hit;
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

template <bool kCount, bool kAnyHit>
Hit trace_counted(const Bvh8View& v, const Ray& ray, RayCounters* c) {
  if constexpr (kCount) ++c->rays;
  if (!is_valid(ray)) return Hit{};
  const auto walk = [&] {
    if (v.subtree)
      return ray.tnear >= 0.0f ? trace_kernel<kCount, false, kAnyHit, true>(v, ray, c)
                               : trace_kernel<kCount, true, kAnyHit, true>(v, ray, c);
    return ray.tnear >= 0.0f ? trace_kernel<kCount, false, kAnyHit, false>(v, ray, c)
                             : trace_kernel<kCount, true, kAnyHit, false>(v, ray, c);
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
  return c ? trace_counted<true, false>(view, ray, c) : trace_counted<false, false>(view, ray, nullptr);
}

void BSPRT_BVH8_BATCH(const Bvh8View& view, const Ray* rays, Hit* hits, std::size_t n, RayCounters* c,
                      Bvh8FallbackFn fallback, const void* ctx) {
  for (std::size_t i = 0; i < n; ++i) {
    const Ray& r = rays[i];
    if (!bvh8_origin_in_range(r)) hits[i] = fallback(ctx, r, c);
    else hits[i] = c ? trace_counted<true, false>(view, r, c) : trace_counted<false, false>(view, r, nullptr);
  }
}

bool BSPRT_BVH8_OCCLUDED(const Bvh8View& view, const Ray& ray, RayCounters* c) {
  return (c ? trace_counted<true, true>(view, ray, c) : trace_counted<false, true>(view, ray, nullptr)).hit();
}

}  // namespace bsprt::detail
