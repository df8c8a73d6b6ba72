/// \file watertight_packet_sse42.cpp
/// Brute-force packet kernel, W = 4, compiled with the sse42 flags set in
/// traverse/CMakeLists.txt (one source: watertight_packet_brute.inl).
#include "traverse/simd/watertight_packet_brute.inl"

namespace bsprt::detail {

void brute_force_packets_sse42(const TriangleSoup& soup, std::span<const std::uint32_t> live,
    std::span<const Ray> rays, std::span<Hit> hits, RayCounters* counters) {
  simd::brute_force_packets<4>(soup, live, rays, hits, counters);
}

}  // namespace bsprt::detail
