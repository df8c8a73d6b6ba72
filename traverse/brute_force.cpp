/// \file brute_force.cpp
/// The brute-force oracle (scalar) and the dispatcher of its packet kernels.
#include "traverse/brute_force.h"

#include <string>
#include <vector>

#include "bsprt/error.h"
#include "traverse/simd/cpu_features.h"
#include "traverse/watertight.h"
#include "traverse/simd/watertight_packet_brute.h"

namespace bsprt {

BruteForceTracer::BruteForceTracer(const TriangleSoup& soup) : soup_(soup) {}

Hit BruteForceTracer::trace(const Ray& ray, RayCounters* counters) const {
  Hit hit;
  if (counters) ++counters->rays;
  const WatertightRay r = watertight_precompute(ray);
  if (!r.valid) return hit;
  std::uint64_t tests = 0;
  const std::uint32_t n = std::uint32_t(soup_.size());
  for (std::uint32_t i = 0; i < n; ++i) {
    if (soup_.is_degenerate(i)) continue;
    ++tests;
    intersect_watertight_closest(r, soup_.corner(i, 0), soup_.corner(i, 1), soup_.corner(i, 2), i,
                                 hit);
  }
  if (counters) counters->triangle_tests += tests;
  return hit;
}

namespace {
/// Single rays, the fallback of every width.
void trace_singles(const TriangleSoup& soup, std::span<const Ray> rays, std::span<Hit> hits,
                   RayCounters* counters) {
  const BruteForceTracer tracer(soup);
  for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = tracer.trace(rays[i], counters);
}
}  // namespace

void brute_force_trace_batch(const TriangleSoup& soup, std::span<const Ray> rays,
                             std::span<Hit> hits, int packet_width, RayCounters* counters) {
  if (hits.size() != rays.size())
    throw UsageError("brute_force_trace_batch: " + std::to_string(rays.size()) + " rays but " +
                     std::to_string(hits.size()) + " hits");
  const Isa need = isa_for_width(packet_width);  // throws UsageError for bad widths
  if (need == Isa::Scalar || int(detected_isa()) < int(need)) {
    trace_singles(soup, rays, hits, counters);
    return;
  }
  std::vector<std::uint32_t> live;
  live.reserve(soup.size());
  for (std::uint32_t i = 0; i < soup.size(); ++i)
    if (!soup.is_degenerate(i)) live.push_back(i);
  switch (need) {
    case Isa::Sse42: detail::brute_force_packets_sse42(soup, live, rays, hits, counters); break;
    case Isa::Avx2: detail::brute_force_packets_avx2(soup, live, rays, hits, counters); break;
    case Isa::Avx512: detail::brute_force_packets_avx512(soup, live, rays, hits, counters); break;
    case Isa::Scalar: break;
  }
}

}  // namespace bsprt
