#include "traverse/simd/cpu_features.h"

#include "bsprt/error.h"

namespace bsprt {

Isa detected_isa() {
  static const Isa isa = [] {
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
        __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
      return Isa::Avx512;
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return Isa::Avx2;
    if (__builtin_cpu_supports("sse4.2")) return Isa::Sse42;
    return Isa::Scalar;
  }();
  return isa;
}

std::string isa_name(Isa isa) {
  switch (isa) {
    case Isa::Scalar: return "scalar";
    case Isa::Sse42: return "sse4.2";
    case Isa::Avx2: return "avx2";
    case Isa::Avx512: return "avx512";
  }
  return "?";
}

Isa parse_isa(const std::string& name) {
  for (Isa i : {Isa::Scalar, Isa::Sse42, Isa::Avx2, Isa::Avx512})
    if (isa_name(i) == name) return i;
  throw UsageError("unknown ISA '" + name + "' (expected scalar, sse4.2, avx2 or avx512)");
}

int isa_width(Isa isa) {
  switch (isa) {
    case Isa::Scalar: return 1;
    case Isa::Sse42: return 4;
    case Isa::Avx2: return 8;
    case Isa::Avx512: return 16;
  }
  return 1;
}

Isa check_trace_batch(std::size_t rays, std::size_t hits, int packet_width) {
  if (hits != rays)
    throw UsageError("trace_batch: " + std::to_string(rays) + " rays but " + std::to_string(hits) + " hits");
  const Isa need = isa_for_width(packet_width);  // UsageError for bad widths
  if (int(detected_isa()) < int(need))
    throw UsageError("packets of " + std::to_string(packet_width) + " rays need " + isa_name(need) +
                     ", this CPU has " + isa_name(detected_isa()));
  return need;
}

Isa isa_for_width(int width) {
  switch (width) {
    case 1: return Isa::Scalar;
    case 4: return Isa::Sse42;
    case 8: return Isa::Avx2;
    case 16: return Isa::Avx512;
    default: throw UsageError("packet width must be 1, 4, 8 or 16, not " + std::to_string(width));
  }
}

}  // namespace bsprt
