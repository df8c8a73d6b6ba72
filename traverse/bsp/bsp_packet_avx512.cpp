/// \file bsp_packet_avx512.cpp
/// BSP packet kernel, W = 16, compiled with the avx512 flags set in
/// traverse/CMakeLists.txt (one source: bsp_packet.inl).
#include "traverse/bsp/bsp_packet.inl"

namespace bsprt::detail {

void bsp_trace_packets_avx512(const BspView& view, const Ray* rays, std::size_t count, Hit* hits,
                          RayCounters* counters) {
  simd::trace_packets_counted<16>(view, rays, count, hits, counters);
}

}  // namespace bsprt::detail
