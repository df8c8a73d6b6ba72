#pragma once
/// \file simd.h
/// Width-templated SIMD vectors on GCC vector extensions, so one kernel source
/// compiles as SSE4.2 (W=4), AVX2 (W=8) and AVX-512 (W=16) in per-ISA
/// translation units (Embree's scheme, STYLE.md point 13).
///
/// ODR: everything here, and every inline function of a header meant for
/// kernels, lives in the inline namespace BSPRT_ISA_NAMESPACE, whose name
/// depends on the instruction set the including translation unit is compiled
/// for. Callers write `bsprt::simd::any(m)` as usual, but the AVX-512
/// instantiation gets a different mangled name from the SSE one, so the linker
/// can never hand AVX-512 code to the SSE path.
///
/// Floating-point contraction: GCC fuses `a*b - c*d` into FMAs when FMA is
/// enabled, which would make the watertight test differ between ISAs (and break
/// the exact antisymmetry of shared edges). `no_fma(x)` hides a product from
/// the optimizer so it is rounded on its own; it costs no instruction.

#include <cstdint>
#include <cstring>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#if defined(__AVX512F__)
#define BSPRT_ISA_NAMESPACE isa_avx512
#elif defined(__AVX2__)
#define BSPRT_ISA_NAMESPACE isa_avx2
#elif defined(__AVX__)
#define BSPRT_ISA_NAMESPACE isa_avx
#elif defined(__SSE4_2__)
#define BSPRT_ISA_NAMESPACE isa_sse42
#else
#define BSPRT_ISA_NAMESPACE isa_base
#endif

namespace bsprt {
inline namespace BSPRT_ISA_NAMESPACE {

/// Returns x unchanged but opaque to the optimizer, so a product passed through
/// it is never fused into an FMA with a following add (bit-identical results
/// on every ISA). Works for float, double and GCC vector types.
template <typename T>
inline __attribute__((always_inline)) T no_fma(T x) {
#if defined(__x86_64__) || defined(__i386__)
  asm("" : "+x"(x));
#else
  asm("" : "+g"(x));
#endif
  return x;
}

}  // namespace BSPRT_ISA_NAMESPACE
}  // namespace bsprt

namespace bsprt::simd {
inline namespace BSPRT_ISA_NAMESPACE {

/// The GCC vector types of width W (4, 8 or 16 lanes of 32 bits).
template <int W>
struct VecTypes {
  static_assert(W == 4 || W == 8 || W == 16, "SIMD width must be 4, 8 or 16");
  typedef float F __attribute__((vector_size(4 * W)));
  typedef std::int32_t I __attribute__((vector_size(4 * W)));
};

/// W floats. Arithmetic and comparisons are the built-in vector operators;
/// `a < b` yields a vmask<W>; scalars broadcast in mixed expressions.
template <int W>
using vfloat = typename VecTypes<W>::F;
/// W int32s.
template <int W>
using vint = typename VecTypes<W>::I;
/// Lane mask: each lane is -1 (true) or 0 (false), as vector comparisons yield.
template <int W>
using vmask = vint<W>;

/// GCC vectors of W doubles and the W int64 lane masks their comparisons yield
/// (the exact leaves' double stage, exact_packet_stage.h).
template <int W>
struct VecDoubles {
  typedef double D __attribute__((vector_size(8 * W)));
  typedef std::int64_t M __attribute__((vector_size(8 * W)));
};
template <int W>
using vdouble = typename VecDoubles<W>::D;
template <int W>
using vmask64 = typename VecDoubles<W>::M;

/// All lanes equal to x.
template <int W>
inline vfloat<W> splat(float x) {
  return vfloat<W>{} + x;
}
/// All lanes equal to x.
template <int W>
inline vint<W> splat_int(std::int32_t x) {
  return vint<W>{} + x;
}
/// All lanes true (-1).
template <int W>
inline vmask<W> mask_true() {
  return vint<W>{} - 1;
}
/// All lanes false.
template <int W>
inline vmask<W> mask_false() {
  return vint<W>{};
}

/// Per lane: m ? a : b (m a vmask).
template <int W>
inline vfloat<W> select(vmask<W> m, vfloat<W> a, vfloat<W> b) {
  return m ? a : b;
}
/// Per lane: m ? a : b (m a vmask).
template <int W>
inline vint<W> select(vmask<W> m, vint<W> a, vint<W> b) {
  return m ? a : b;
}

/// Bit i set when lane i of m is true.
template <int W>
inline unsigned movemask(vmask<W> m) {
#if defined(__AVX512F__)
  if constexpr (W == 16) return _mm512_cmplt_epi32_mask(reinterpret_cast<__m512i>(m), _mm512_setzero_si512());
#endif
#if defined(__AVX__)
  if constexpr (W == 8) return unsigned(_mm256_movemask_ps(reinterpret_cast<__m256>(m)));
#endif
#if defined(__SSE2__)
  if constexpr (W == 4) return unsigned(_mm_movemask_ps(reinterpret_cast<__m128>(m)));
#endif
  unsigned bits = 0;
  for (int i = 0; i < W; ++i) bits |= (m[i] != 0 ? 1u : 0u) << i;
  return bits;
}
/// True when some lane of m is true.
template <int W>
inline bool any(vmask<W> m) {
  return movemask<W>(m) != 0;
}
/// True when no lane of m is true.
template <int W>
inline bool none(vmask<W> m) {
  return movemask<W>(m) == 0;
}
/// True when every lane of m is true.
template <int W>
inline bool all(vmask<W> m) {
  return movemask<W>(m) == (1u << W) - 1u;
}

/// Per-lane absolute value (clears the sign bit; NaN stays NaN).
template <int W>
inline vfloat<W> abs(vfloat<W> a) {
  return reinterpret_cast<vfloat<W>>(reinterpret_cast<vint<W>>(a) & 0x7fffffff);
}
/// Per-lane minimum; returns b where a is NaN.
template <int W>
inline vfloat<W> min(vfloat<W> a, vfloat<W> b) {
  return a < b ? a : b;
}
/// Per-lane maximum; returns b where a is NaN.
template <int W>
inline vfloat<W> max(vfloat<W> a, vfloat<W> b) {
  return a > b ? a : b;
}
/// Per-lane NaN test.
template <int W>
inline vmask<W> is_nan(vfloat<W> a) {
  return a != a;
}

/// Unaligned load of W floats.
template <int W>
inline vfloat<W> load(const float* p) {
  vfloat<W> v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}
/// Unaligned store of W floats.
template <int W>
inline void store(float* p, vfloat<W> v) {
  std::memcpy(p, &v, sizeof(v));
}
/// Unaligned load of W int32s.
template <int W>
inline vint<W> load_int(const std::int32_t* p) {
  vint<W> v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}

}  // namespace BSPRT_ISA_NAMESPACE
}  // namespace bsprt::simd
