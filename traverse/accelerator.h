#pragma once
/// \file accelerator.h
/// The one interface every accelerator and oracle implements (brute force, kd,
/// BSP, Embree), so the CLI, tests and benchmarks can swap them by name.

#include <cstddef>
#include <memory>
#include <span>
#include <string>

#include "bsprt/ray.h"
#include "traverse/counters.h"

namespace bsprt {

/// Nearest-hit ray tracer over one fixed scene.
///
/// Every method expects IEEE default arithmetic on the calling thread (no
/// flush-to-zero, no denormals-are-zero, round to nearest): the certified
/// bounds and the exact filters assume it, and a per-ray guard would cost every
/// ray. Callers set it: trace_parallel's tasks, the CLI and the public API
/// (bsprt::Tracer) run under geometry/core/fp_env.h's IeeeScope.
class Accelerator {
 public:
  virtual ~Accelerator() = default;

  /// Short name as used by `--accel` ("brute", "kd", "bsp", "embree").
  virtual std::string name() const = 0;

  /// Nearest hit of one ray in [tnear, tfar]; invalid rays miss. Adds its work
  /// to `counters` when non-null. Must be safe to call from many threads.
  virtual Hit trace(const Ray& ray, RayCounters* counters = nullptr) const = 0;

  /// Traces rays[i] into hits[i] (hits.size() == rays.size()), from one thread.
  /// Coherent batches may use packets of `packet_width` rays (1 = single rays);
  /// the default loops over `trace`. Results must equal single-ray results.
  virtual void trace_batch(std::span<const Ray> rays, std::span<Hit> hits, int packet_width = 1,
                           RayCounters* counters = nullptr) const {
    (void)packet_width;
    for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = trace(rays[i], counters);
  }

  /// Whether the ray hits anything in [tnear, tfar] (shadow and any-hit rays):
  /// exactly trace(ray).hit(). A tracer may stop at the first hit it finds
  /// (the BVH8 does); the default traces the nearest hit. Counts as trace does.
  virtual bool occluded(const Ray& ray, RayCounters* counters = nullptr) const {
    return trace(ray, counters).hit();
  }

  /// Bytes held by the acceleration structure (0 for brute force).
  virtual std::size_t memory_bytes() const { return 0; }
};

}  // namespace bsprt
