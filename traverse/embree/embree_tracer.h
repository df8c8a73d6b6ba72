#pragma once
/// \file embree_tracer.h
/// Embree 3 behind the Accelerator interface: the peer in benchmarks, an oracle in
/// tests. Robust mode (RTC_SCENE_FLAG_ROBUST) by default, as in the design's
/// error measurements; the default mode can be asked for to measure it too.

#include <memory>

#include "geometry/core/triangle_soup.h"
#include "traverse/accelerator.h"

namespace bsprt {

/// Embree options.
struct EmbreeConfig {
  bool robust = true;  ///< RTC_SCENE_FLAG_ROBUST: Embree's watertight-ish mode
  bool high_quality = true;  ///< RTC_BUILD_QUALITY_HIGH (SAH with spatial splits)
};

/// Why Embree cannot trace the valid ray `r`, or nullptr when it can (or `r`
/// is invalid, a miss without Embree). Embree asserts tnear >= 0 and origin
/// and direction components at most 1.844e18 (FLT_LARGE) in magnitude; Debian's
/// build keeps the assertions, so such a ray would abort the process.
const char* embree_cannot_trace(const Ray& r);

/// Embree 3 scene over the soup. Degenerate triangles are not given to Embree;
/// a table maps Embree primIDs back to our triangle numbers. Invalid rays
/// (is_valid) are misses; a valid ray Embree cannot trace (tnear < 0, or an
/// origin or direction component above 1.844e18 in magnitude) is a UsageError
/// naming it (index within the batch), thrown before any ray of the batch is traced.
class EmbreeTracer final : public Accelerator {
 public:
  EmbreeTracer(const TriangleSoup& soup, const EmbreeConfig& config = {});
  ~EmbreeTracer() override;
  std::string name() const override;
  Hit trace(const Ray& ray, RayCounters* counters = nullptr) const override;
  /// packet_width 4/8/16 uses rtcIntersect4/8/16; 1 uses rtcIntersect1.
  void trace_batch(std::span<const Ray> rays, std::span<Hit> hits, int packet_width = 1,
                   RayCounters* counters = nullptr) const override;
  /// rtcOccluded1: Embree's any-hit query (same domain checks as trace).
  bool occluded(const Ray& ray, RayCounters* counters = nullptr) const override;
  std::size_t memory_bytes() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bsprt
