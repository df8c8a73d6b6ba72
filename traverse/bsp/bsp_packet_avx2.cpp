/// \file bsp_packet_avx2.cpp
/// BSP packet kernel, W = 8, compiled with the avx2 flags set in
/// traverse/CMakeLists.txt (one source: bsp_packet.inl).
#include "traverse/bsp/bsp_packet.inl"

namespace bsprt::detail {

void bsp_trace_packets_avx2(const BspView& view, const Ray* rays, std::size_t count, Hit* hits,
                          RayCounters* counters) {
  simd::trace_packets_counted<8>(view, rays, count, hits, counters);
}

}  // namespace bsprt::detail
