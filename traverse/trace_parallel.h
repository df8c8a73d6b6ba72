#pragma once
/// \file trace_parallel.h
/// Tracing a span of rays in parallel blocks over the current oneTBB arena:
/// the one loop the CLI, `bsprt bench`, the public API and the tests share.
/// Hits do not depend on the block size, the thread count or the order the
/// blocks run in (each ray's hit is a function of the ray alone).

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/combinable.h>
#include <oneapi/tbb/parallel_for.h>

#include <cstddef>
#include <functional>
#include <span>

#include "bsprt/ray.h"
#include "geometry/core/fp_env.h"
#include "traverse/accelerator.h"
#include "traverse/counters.h"

namespace bsprt {

/// How trace_parallel splits and traces the rays.
struct ParallelTrace {
  int packet_width = 1;     ///< Accelerator::trace_batch's packet width (1 = single rays)
  bool count = false;       ///< sum the accelerator's work counters (costs time)
  std::size_t block = 4096; ///< rays per task
  /// Called after each block with its size, from the thread that traced it
  /// (progress bars).
  std::function<void(std::size_t)> on_block;
};

/// Runs body(begin, end) over [0, n) in blocks of `block`, on the current
/// arena, in IEEE arithmetic on every thread whatever the caller's thread or
/// arena holds (geometry/core/fp_env.h: the certified bounds assume it).
template <typename Body>
void for_each_block(std::size_t n, std::size_t block, Body&& body) {
  IeeeTasks ieee;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, block),
      [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); }, ieee.context());
}

/// hits[i] = the accelerator's nearest hit of rays[i] (hits.size() == rays.size()),
/// block by block with trace_batch; returns the summed counters (zero unless
/// options.count).
inline RayCounters trace_parallel(const Accelerator& accel, std::span<const Ray> rays, std::span<Hit> hits,
                                  const ParallelTrace& options = {}) {
  tbb::combinable<RayCounters> counters;
  for_each_block(rays.size(), options.block, [&](std::size_t b, std::size_t e) {
    accel.trace_batch(rays.subspan(b, e - b), hits.subspan(b, e - b), options.packet_width,
                      options.count ? &counters.local() : nullptr);
    if (options.on_block) options.on_block(e - b);
  });
  return counters.combine([](RayCounters a, const RayCounters& b) { return a += b; });
}

}  // namespace bsprt
