#pragma once
/// \file bsp_kernel.h
/// Internal to the BSP traversal: the certified interval arithmetic of one
/// node step, written once for float and for SIMD vectors (vfloat<W>) so the
/// scalar traversal (bsp_traverse.cpp) and the per-ISA packet kernels
/// (bsp_packet.inl) perform the same IEEE operations in the same order (all
/// these files are compiled with -ffp-contract=off), hence bit-identical
/// intervals. The derivation of every constant is in docs/certified-epsilons.md.
///
/// Everything inline lives in the ISA inline namespace of simd.h (ODR: the
/// AVX-512 copy of an inline function must never serve the baseline caller).

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "bsprt/ray.h"
#include "traverse/bsp/bsp_compact.h"
#include "traverse/bsp/bsp_node.h"
#include "traverse/leaf_intersector.h"
#include "traverse/counters.h"
#include "traverse/simd/simd.h"
#include "traverse/stack_step.h"

namespace bsprt {

namespace detail {

/// Widening of a computed crossing parameter q: the interval of a child is
/// clipped at up(q) = max(q·(1+2^-21), q·(1-2^-21)) + 2^-126 (or dn(q), the
/// mirror), more than the γ_3 ≈ 3u relative error of q and its own rounding;
/// 2^-126 covers underflow. Docs §3.
inline constexpr float kWidenHi = 1.0f + 0x1p-21f;
inline constexpr float kWidenLo = 1.0f - 0x1p-21f;
inline constexpr float kTiny = 0x1p-126f;
/// Upper bound of ‖n‖₁ of every plane node's float normal (√3 for a unit
/// vector, checked by flatten and FlatBspTree::validate()).
inline constexpr float kNormL1Max = 1.7321f;
/// Per-ray error coefficients: err_o = kErrCoef·max|o_i| + kErrAbs bounds (twice
/// over) the γ_4 rounding of n·o, err_d = kErrCoef·max|dir_i| + kErrAbs the γ_3
/// rounding of n·dir plus the flush of a subnormal slope. kErrCoef = 8u·‖n‖₁.
inline constexpr float kErrCoef = kNormL1Max * 0x1p-21f;
inline constexpr float kErrAbs = 0x1p-120f;
/// Rays outside this magnitude range are traced in the fallback mode where
/// every node passes both children (correct, slow): |o_i| <= 2^64, and
/// 2^-64 <= max|dir_i| <= 2^64.
inline constexpr float kSafeMax = 0x1p64f;
inline constexpr float kSafeMinDir = 0x1p-64f;

/// Raw view of a BspTracer for kernels that must not instantiate std::
/// templates compiled for their ISA.
struct BspView {
  const CompactBspSlot* nodes;   ///< the traversal layout (bsp_compact.h)
  const std::uint32_t* prims;
  const BspTriangle* triangles;  ///< parallel to prims
  Box3f bounds;                  ///< root cell
  bool certified;                ///< false: the zero-epsilon variant (per-ray errors 0)
  const LeafIntersector* exact_leaf = nullptr;  ///< exact-decision leaf test, or null = watertight float
};

/// Per-ray constants of the traversal, made once per ray by bsp_ray_setup.
struct BspRayConst {
  float o[3];        ///< origin
  float dir[3];      ///< direction of the traversal: the ray's, or scaled into range (scale_direction)
  float inv[3];      ///< 1/dir_k; NaN when dir_k is subnormal or the ray is unsafe
  bool neg[3];       ///< sign bit of inv[k]: kd near child is the upper one
  float err;         ///< err_o + err_d·T: certified error of n·(o + t·dir) + d for every t of
                     ///< the clipped segment, T = max(|tmin|, |tmax|) (inf: unsafe ray)
  float tmin, tmax;  ///< ray segment clipped (conservatively) to the root cell
  bool live;         ///< valid ray with a non-empty clipped segment
  bool scaled;       ///< traversal parameters are the ray's t times hit_scale (scale_direction)
  float hit_scale;   ///< 2^e of scale_direction; 1 when not scaled
};

/// Single-ray trace used by kernels for lanes that leave a packet.
using BspSingleFn = Hit (*)(const BspView& view, const Ray& ray, RayCounters* counters);

/// Packet kernels: rays[0..count) into hits, W = 4 / 8 / 16 at a time. Call only
/// when detected_isa() supports them. Results and counters equal single rays.
void bsp_trace_packets_sse42(const BspView& view, const Ray* rays, std::size_t count, Hit* hits,
                             RayCounters* counters);
void bsp_trace_packets_avx2(const BspView& view, const Ray* rays, std::size_t count, Hit* hits,
                            RayCounters* counters);
void bsp_trace_packets_avx512(const BspView& view, const Ray* rays, std::size_t count, Hit* hits,
                              RayCounters* counters);

inline namespace BSPRT_ISA_NAMESPACE {

/// |x| for float and vfloat alike (NaN stays NaN; -0 stays -0, which compares
/// equal to 0).
template <typename F>
inline F gabs(F x) {
  return x < 0.0f ? -x : x;
}
/// Scalar |x| without a branch (GCC compiles the select above to one for
/// floats, mispredicted on random rays). Differs only on -0 (gives +0), which
/// compares equal to it.
inline float gabs(float x) { return std::fabs(x); }

/// How a node step widens its crossing q into the near child's upper end up(q)
/// and the far child's lower end dn(q):
///  - Ordered: widen_up / widen_dn, max and min of q·(1±2^-21), any ray;
///  - NonNegative: q·(1+2^-21) + 2^-126 and q·(1-2^-21) − 2^-126, no max or
///    min, for rays whose clipped segment starts at t >= 0. The two agree bit
///    for bit unless q is finite and negative; then the computed q has the sign
///    of the exact crossing (a rounded difference and a rounded quotient or
///    product keep their signs), so the whole plane side that the far child
///    takes lies at t >= 0 > q: the far child is entered from tmin (far_min =
///    max(dn, tmin) = tmin for either dn < 0), and the near child holds no point
///    of the segment, so whether it is visited changes no hit
///    (docs/certified-epsilons.md §4);
///  - PerLane: NonNegative in the lanes of the mask `nonneg`, Ordered in the
///    others, so a packet lane computes what its single ray computes.
enum class Order { Ordered, NonNegative, PerLane };

/// up(q) as kOrder says (see Order).
template <Order kOrder, typename F, typename M>
inline F widen_up_as(F q, M nonneg) {
  const F a = q * kWidenHi, b = q * kWidenLo;
  if constexpr (kOrder == Order::NonNegative) return a + kTiny;
  else if constexpr (kOrder == Order::Ordered) return (a > b ? a : b) + kTiny;
  else return (nonneg ? a : (a > b ? a : b)) + kTiny;
}
/// dn(q) as kOrder says (see Order).
template <Order kOrder, typename F, typename M>
inline F widen_dn_as(F q, M nonneg) {
  const F a = q * kWidenHi, b = q * kWidenLo;
  if constexpr (kOrder == Order::NonNegative) return b - kTiny;
  else if constexpr (kOrder == Order::Ordered) return (a < b ? a : b) - kTiny;
  else return (nonneg ? b : (a < b ? a : b)) - kTiny;
}

/// Conservative upper end of a crossing parameter (see kWidenHi), for any ray.
/// NaN stays NaN and then means "no constraint" at the caller.
template <typename F>
inline F widen_up(F q) {
  return widen_up_as<Order::Ordered>(q, false);
}
/// Conservative lower end of a crossing parameter, for any ray.
template <typename F>
inline F widen_dn(F q) {
  return widen_dn_as<Order::Ordered>(q, false);
}

/// kd node on axis k: crossing t = (split - o_k)·(1/dir_k), widened. Near is the
/// lower child unless dir_k is negative. dir_k = ±0 gives ±inf (the ray stays on
/// one side), a ray in the plane gives NaN (both children, whole interval).
template <typename F, Order kOrder = Order::Ordered, typename M = bool>
inline void kd_cut(float split, F o_k, F inv_k, F& near_hi, F& far_lo, M nonneg = M{}) {
  const F t = (split - o_k) * inv_k;
  near_hi = widen_up_as<kOrder>(t, nonneg);
  far_lo = widen_dn_as<kOrder>(t, nonneg);
}

/// Plane node in slots n[0..2] (bsp_compact.h) (docs/certified-epsilons.md
/// §2-3): a = fl(n·o + d), b = fl(n·dir)
/// (flushed to +0 when subnormal), E = eps + err (err: the ray's, BspRayConst)
/// bounds |exact plane(o + t·dir) − (a + b·t)| over the cell for every t of
/// the ray's clipped segment, hence of every node interval inside it. E does
/// not depend on the node's interval, so consecutive plane steps do not wait
/// on each other. The first child (value <= 0) needs a + b·t <= E, the second
/// a + b·t >= −E. Returns the slope b: near is the first child iff b >= 0.
/// kOrder, nonneg: as for kd_cut.
template <typename F, Order kOrder = Order::Ordered, typename M = bool>
inline F plane_cut(const CompactBspSlot* n, const F (&o)[3], const F (&dir)[3], F err, F& near_hi,
                   F& far_lo, M nonneg = M{}) {
  const float n0 = n->plane_normal(0), n1 = n->plane_normal(1), n2 = n->plane_normal(2), d = n->plane_d(),
              eps = n->plane_eps();
  const F a = ((n0 * o[0] + n1 * o[1]) + n2 * o[2]) + d;
  F b = (n0 * dir[0] + n1 * dir[1]) + n2 * dir[2];
  b = gabs(b) < kTiny ? F{} : b;
  const F e = eps + err;
  const F inv = 1.0f / b;
  const F q_first = (e - a) * inv, q_second = (-e - a) * inv;
  const auto flip = b < 0.0f;
  if constexpr (std::is_same_v<F, float> && kOrder == Order::PerLane) {
    // The interleaved kernel (PerLane on one ray): flip ? q_second : q_first
    // by mask. As a ?: GCC branches on the slope's sign, which the kernel's
    // lanes in round robin mispredict (1.4 a random bunny ray, cachegrind).
    // Not in the sequential walk: there the branch is predicted and the mask
    // lengthens the step's latency (suzanne camera rays 7-13 % slower).
    const std::uint32_t m = 0u - std::uint32_t(flip);
    near_hi = widen_up_as<kOrder>(select_bits(m, q_second, q_first), nonneg);
    far_lo = widen_dn_as<kOrder>(select_bits(m, q_first, q_second), nonneg);
  } else {
    near_hi = widen_up_as<kOrder>(flip ? q_second : q_first, nonneg);
    far_lo = widen_dn_as<kOrder>(flip ? q_first : q_second, nonneg);
  }
  return b;
}

/// Sign bit of x: a bool for float, a lane mask for SIMD vectors.
inline bool sign_of(float x) { return std::signbit(x); }
template <typename F>
inline auto sign_of(F x) {
  using M = decltype(x < x);
  return reinterpret_cast<M>(x) < 0;
}

/// The arithmetic of bsp_ray_setup, written once for one ray (F = float,
/// masks bool) and for W lanes (F = vfloat<W>, masks vmask<W>): the packet
/// kernels run the same IEEE operations in the same order, so each lane's
/// values are its single ray's bit for bit. In: origin, direction, and in
/// tmin/tmax the ray's tnear/tfar. Out: reciprocals (NaN when dir_k is
/// subnormal or the ray is unsafe), their sign bits, the segment clipped to
/// the root box with widened slab crossings (NaN slabs, from a ray in a slab
/// plane or a subnormal direction component, do not clip), and err (§3).
///
/// kByMask (one ray, F = float): the root box's near and far slab crossings
/// chosen by mask instead of a branch on the direction's signs, for
/// incoherent rays, which mispredict that branch (1.5 a random bunny ray,
/// cachegrind). Coherent rays predict it, and there the mask cost camera
/// rays 6 % (suzanne). The values are the same bit for bit either way.
template <typename F, typename M, bool kByMask = false>
inline void ray_setup_core(const F (&o)[3], const F (&dir)[3], const Box3f& root, bool certified,
                           F (&inv)[3], M (&neg)[3], F& tmin, F& tmax, F& err) {
  F mo{}, md{};
  for (int k = 0; k < 3; ++k) {
    const F ao = gabs(o[k]), ad = gabs(dir[k]);
    mo = ao > mo ? ao : mo;
    md = ad > md ? ad : md;
  }
  const auto safe = (mo <= kSafeMax) & (md <= kSafeMax) & (md >= kSafeMinDir);
  const F nan = F{} + std::numeric_limits<float>::quiet_NaN();
  for (int k = 0; k < 3; ++k) {
    const auto normal_or_zero = (dir[k] == 0.0f) | (gabs(dir[k]) >= kTiny);
    inv[k] = (safe & normal_or_zero) ? 1.0f / dir[k] : nan;
    neg[k] = sign_of(inv[k]);
  }
  const F err_o = safe ? (certified ? kErrCoef * mo + kErrAbs : F{})
                       : F{} + std::numeric_limits<float>::infinity();
  const F err_d = certified ? kErrCoef * md + kErrAbs : F{};
  // The slab crossings' max (min) is widened once: widen_dn and widen_up are
  // monotone, so this equals the max (min) of the widened crossings, bit for
  // bit. NaN crossings do not clip (a comparison with NaN keeps the bound).
  const F inf = F{} + std::numeric_limits<float>::infinity();
  F enter = -inf, exit = inf;
  for (int k = 0; k < 3; ++k) {
    const F ta = (root.lo[k] - o[k]) * inv[k], tb = (root.hi[k] - o[k]) * inv[k];
    F e, x;
    if constexpr (std::is_same_v<F, float> && kByMask) {
      // neg[k] ? tb : ta by mask (a ?: on floats is a branch with GCC). Not
      // min/max: those differ from the select when one crossing is NaN (an
      // origin on a slab plane, dir_k = 0). Not the three axes in one SSE
      // vector either: building it from the scalars made camera rays 7 %
      // slower (suzanne), likely store forwarding.
      const std::uint32_t m = 0u - std::uint32_t(neg[k]);
      e = select_bits(m, tb, ta), x = select_bits(m, ta, tb);
    } else {
      e = neg[k] ? tb : ta, x = neg[k] ? ta : tb;
    }
    enter = e > enter ? e : enter;
    exit = x < exit ? x : exit;
  }
  enter = widen_dn(enter);
  exit = widen_up(exit);
  tmin = enter > tmin ? enter : tmin;
  tmax = exit < tmax ? exit : tmax;
  const F at0 = gabs(tmin), at1 = gabs(tmax);
  err = err_o + err_d * (at0 > at1 ? at0 : at1);
}

/// A valid ray whose origin is in the safe range but whose direction is not
/// (max|dir_k| above kSafeMax or below kSafeMinDir) would take the slow
/// fallback at every node. o + t·d = o + t'·d' with d' = d·2^-e and
/// t' = t·2^e, so the traversal may follow (o, d') over [tnear·2^e, tfar·2^e]
/// instead, with 2^e <= max|dir_k| < 2^(e+1): the same points, a direction in
/// [1, 2), a safe ray (docs/certified-epsilons.md §4). Callers decide the
/// direction's range first (scale_if_out_of_range, the packet setup). Done only when every
/// scaled value is exact (scaling it back gives the original); otherwise
/// nothing changes (an invalid ray is never scaled: NaN and inf fail the
/// checks). Returns whether it scaled; `hit_scale` = 2^e. Scalar (libm's
/// ldexpf, ilogbf), also used lane by lane by the packet setup, so lanes
/// equal single rays.
[[gnu::cold, gnu::noinline]] inline bool scale_direction(const float (&o)[3], float (&dir)[3], float& tnear,
                                                         float& tfar, float& hit_scale) {
  float mo = 0.0f, md = 0.0f;
  for (int k = 0; k < 3; ++k) {
    mo = std::fabs(o[k]) > mo ? std::fabs(o[k]) : mo;
    md = std::fabs(dir[k]) > md ? std::fabs(dir[k]) : md;
  }
  if (!(mo <= kSafeMax) || !(md > 0.0f) || !(md <= std::numeric_limits<float>::max())) return false;
  const int e = __builtin_ilogbf(md);  // -149..127 when md is finite and non-zero
  float d[3];
  for (int k = 0; k < 3; ++k) {
    d[k] = __builtin_ldexpf(dir[k], -e);
    if (__builtin_ldexpf(d[k], e) != dir[k]) return false;  // a subnormal result rounded
  }
  const float t0 = __builtin_ldexpf(tnear, e), t1 = __builtin_ldexpf(tfar, e);
  if (__builtin_ldexpf(t0, -e) != tnear || __builtin_ldexpf(t1, -e) != tfar) return false;
  for (int k = 0; k < 3; ++k) dir[k] = d[k];
  tnear = t0, tfar = t1;
  hit_scale = __builtin_ldexpf(1.0f, e);
  return true;
}

/// The traversal's bound for a hit at `hit_t` (the ray's own t): hit_t, or
/// for a scaled ray hit_t·hit_scale widened up. The widening covers what the
/// unscaled traversal's margins cover for hit_t itself, scaled: a relative
/// error (widen_up's 2^-21) and an absolute one, 2^-150 in t for a subnormal
/// hit_t, which is hit_scale·2^-150 in the traversal's parameter (added as
/// hit_scale·2^-149; it underflows to 0 only when widen_up's 2^-126 already
/// covers it) and 2^-150 for a subnormal product.
template <typename F, typename M>
inline F hit_bound(F hit_t, M scaled, F hit_scale) {
  return scaled ? widen_up(hit_t * hit_scale) + hit_scale * 0x1p-149f : hit_t;
}

/// scale_direction for a direction out of range; the common case, a direction
/// in range, is decided inline.
inline bool scale_if_out_of_range(const float (&o)[3], float (&dir)[3], float& tnear, float& tfar,
                                  float& hit_scale) {
  float md = 0.0f;
  for (int k = 0; k < 3; ++k) md = gabs(dir[k]) > md ? gabs(dir[k]) : md;
  if (__builtin_expect(md <= kSafeMax && md >= kSafeMinDir, 1)) return false;
  return scale_direction(o, dir, tnear, tfar, hit_scale);
}

/// Per-ray constants of one ray (ray_setup_core); an invalid ray is not live.
/// kByMask: see ray_setup_core (for incoherent rays; same values).
template <bool kByMask = false>
inline BspRayConst bsp_ray_setup(const Ray& ray, const Box3f& root, bool certified) {
  BspRayConst c{};
  c.tmin = ray.tnear;
  c.tmax = ray.tfar;
  c.hit_scale = 1.0f;
  c.live = is_valid(ray);
  if (!c.live) return c;
  for (int k = 0; k < 3; ++k) c.o[k] = ray.org[k], c.dir[k] = ray.dir[k];
  c.scaled = scale_if_out_of_range(c.o, c.dir, c.tmin, c.tmax, c.hit_scale);
  ray_setup_core<float, bool, kByMask>(c.o, c.dir, root, certified, c.inv, c.neg, c.tmin, c.tmax, c.err);
  c.live = c.tmin <= c.tmax;
  return c;
}

/// The traversal's bound for the ray's nearest hit so far (hit_bound).
inline float hit_bound(const BspRayConst& c, float hit_t) {
  return __builtin_expect(c.scaled, 0) ? hit_bound<float, bool>(hit_t, true, c.hit_scale) : hit_t;
}

}  // namespace BSPRT_ISA_NAMESPACE
}  // namespace detail
}  // namespace bsprt
