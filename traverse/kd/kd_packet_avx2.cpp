/// \file kd_packet_avx2.cpp
/// kd packet kernel, W = 8, compiled with the avx2 flags set in
/// traverse/CMakeLists.txt (one source: kd_packet.inl).
#include "traverse/kd/kd_packet.inl"

namespace bsprt::detail {

void kd_trace_packets_avx2(const KdView& view, const Ray* rays, std::size_t count, Hit* hits,
                         RayCounters* counters, KdSingleFn single) {
  simd::trace_packets_counted<8>(view, rays, count, hits, counters, single);
}

}  // namespace bsprt::detail
