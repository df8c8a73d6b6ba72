#pragma once
/// \file watertight_packet_brute.h
/// Brute force with packets: W rays at a time against every triangle, using the
/// packet watertight test. Kernels are compiled once per ISA
/// (watertight_packet_{sse42,avx2,avx512}.cpp from watertight_packet_brute.inl)
/// and chosen at run time; results equal BruteForceTracer::trace bit for bit.

#include <cstdint>
#include <span>

#include "bsprt/ray.h"
#include "geometry/core/triangle_soup.h"
#include "traverse/counters.h"

namespace bsprt {

/// Traces rays[i] into hits[i] by brute force in packets of `packet_width`
/// (1, 4, 8 or 16). A width whose ISA this CPU lacks (cpu_features.h) falls
/// back to single rays. Counters count rays and ray/triangle tests per ray, as
/// the scalar path does. Throws UsageError for another width or when
/// hits.size() != rays.size().
void brute_force_trace_batch(const TriangleSoup& soup, std::span<const Ray> rays,
                             std::span<Hit> hits, int packet_width, RayCounters* counters);

namespace detail {
/// Per-ISA kernels behind brute_force_trace_batch; call only when
/// detected_isa() supports them.
/// `live` lists the non-degenerate triangles in order.
void brute_force_packets_sse42(const TriangleSoup& soup, std::span<const std::uint32_t> live,
                               std::span<const Ray> rays, std::span<Hit> hits, RayCounters* counters);
void brute_force_packets_avx2(const TriangleSoup& soup, std::span<const std::uint32_t> live,
                              std::span<const Ray> rays, std::span<Hit> hits, RayCounters* counters);
void brute_force_packets_avx512(const TriangleSoup& soup, std::span<const std::uint32_t> live,
                                std::span<const Ray> rays, std::span<Hit> hits, RayCounters* counters);
}  // namespace detail

}  // namespace bsprt
