/// \file kd_packet_sse42.cpp
/// kd packet kernel, W = 4, compiled with the sse42 flags set in
/// traverse/CMakeLists.txt (one source: kd_packet.inl).
#include "traverse/kd/kd_packet.inl"

namespace bsprt::detail {

void kd_trace_packets_sse42(const KdView& view, const Ray* rays, std::size_t count, Hit* hits,
                         RayCounters* counters, KdSingleFn single) {
  simd::trace_packets_counted<4>(view, rays, count, hits, counters, single);
}

}  // namespace bsprt::detail
