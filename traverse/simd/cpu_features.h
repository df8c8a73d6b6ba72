#pragma once
/// \file cpu_features.h
/// Run-time choice of SIMD kernels (Embree's per-ISA translation units): each
/// kernel is compiled once per instruction set and the widest one this CPU
/// supports is used, unless the user caps it (`--isa`).

#include <cstddef>
#include <string>

namespace bsprt {

/// Instruction sets we compile kernels for, narrowest first.
enum class Isa { Scalar = 0, Sse42 = 1, Avx2 = 2, Avx512 = 3 };

/// Widest ISA this CPU (and OS) supports, detected once.
Isa detected_isa();
/// Name as printed and as accepted by `--isa`: "scalar", "sse4.2", "avx2", "avx512".
std::string isa_name(Isa isa);
/// Parses an ISA name; throws UsageError for unknown names.
Isa parse_isa(const std::string& name);
/// SIMD width in floats for packet kernels of this ISA (1, 4, 8, 16).
int isa_width(Isa isa);
/// The ISA a packet of `width` rays needs (4 -> SSE4.2, 8 -> AVX2, 16 -> AVX-512).
Isa isa_for_width(int width);
/// The checks every packet-capable Accelerator::trace_batch makes: as many hits
/// as rays, a packet width of 1, 4, 8 or 16 that this CPU can run. Returns the
/// ISA the width needs; throws UsageError otherwise.
Isa check_trace_batch(std::size_t rays, std::size_t hits, int packet_width);

}  // namespace bsprt
