/// \file watertight_packet_avx512.cpp
/// Brute-force packet kernel, W = 16, compiled with the avx512 flags set in
/// traverse/CMakeLists.txt (one source: watertight_packet_brute.inl).
#include "traverse/simd/watertight_packet_brute.inl"

namespace bsprt::detail {

void brute_force_packets_avx512(const TriangleSoup& soup, std::span<const std::uint32_t> live,
    std::span<const Ray> rays, std::span<Hit> hits, RayCounters* counters) {
  simd::brute_force_packets<16>(soup, live, rays, hits, counters);
}

}  // namespace bsprt::detail
