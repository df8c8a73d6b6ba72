/// \file bsp_packet_sse42.cpp
/// BSP packet kernel, W = 4, compiled with the sse42 flags set in
/// traverse/CMakeLists.txt (one source: bsp_packet.inl).
#include "traverse/bsp/bsp_packet.inl"

namespace bsprt::detail {

void bsp_trace_packets_sse42(const BspView& view, const Ray* rays, std::size_t count, Hit* hits,
                          RayCounters* counters) {
  simd::trace_packets_counted<4>(view, rays, count, hits, counters);
}

}  // namespace bsprt::detail
