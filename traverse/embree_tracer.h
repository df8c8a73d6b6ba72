#pragma once
/// \file embree_tracer.h
/// Embree 3 behind the Tracer interface: the peer in benchmarks, an oracle in
/// tests. Robust mode (RTC_SCENE_FLAG_ROBUST) by default, as in the design's
/// error measurements; the default mode can be asked for to measure it too.

#include <memory>

#include "geometry/triangle_soup.h"
#include "traverse/tracer.h"

namespace bsprt {

/// Embree options.
struct EmbreeConfig {
  bool robust = true;  ///< RTC_SCENE_FLAG_ROBUST: Embree's watertight-ish mode
  bool high_quality = true;  ///< RTC_BUILD_QUALITY_HIGH (SAH with spatial splits)
};

/// Embree 3 scene over the soup. Degenerate triangles are not given to Embree;
/// a table maps Embree primIDs back to our triangle numbers.
class EmbreeTracer final : public Tracer {
 public:
  EmbreeTracer(const TriangleSoup& soup, const EmbreeConfig& config = {});
  ~EmbreeTracer() override;
  std::string name() const override;
  Hit trace(const Ray& ray, RayCounters* counters = nullptr) const override;
  /// packet_width 4/8/16 uses rtcIntersect4/8/16; 1 uses rtcIntersect1.
  void trace_batch(std::span<const Ray> rays, std::span<Hit> hits, int packet_width = 1,
                   RayCounters* counters = nullptr) const override;
  std::size_t memory_bytes() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bsprt
