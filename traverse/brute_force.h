#pragma once
/// \file brute_force.h
/// The brute-force oracle: tests every non-degenerate triangle with the
/// watertight test. Slow and obviously right; the reference for tree tests.

#include "geometry/core/triangle_soup.h"
#include "traverse/accelerator.h"
#include "traverse/simd/watertight_packet_brute.h"

namespace bsprt {

/// Tests every triangle of the soup. Holds a reference: `soup` must outlive it.
class BruteForceTracer final : public Accelerator {
 public:
  explicit BruteForceTracer(const TriangleSoup& soup);
  std::string name() const override { return "brute"; }
  Hit trace(const Ray& ray, RayCounters* counters = nullptr) const override;
  /// Packets of 4/8/16 rays against every triangle (per-ISA kernels).
  void trace_batch(std::span<const Ray> rays, std::span<Hit> hits, int packet_width = 1,
                   RayCounters* counters = nullptr) const override {
    brute_force_trace_batch(soup_, rays, hits, packet_width, counters);
  }

 private:
  const TriangleSoup& soup_;
};

}  // namespace bsprt
