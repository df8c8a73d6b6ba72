#pragma once
/// \file blocks.h
/// Internal to the API (api/): how a span of rays or points is split over
/// threads, in IEEE arithmetic (fp_env.h), for every call with a `threads`
/// option (TraceOptions, QueryOptions).
#include <oneapi/tbb/task_arena.h>

#include <cstddef>

#include "geometry/core/fp_env.h"
#include "traverse/trace_parallel.h"

namespace bsprt::api {

/// Runs body(begin, end) over [0, n): on the calling thread (threads = 1) or in
/// blocks of 4096 on an arena of `threads` (0 = all cores). The caller has
/// checked `threads` (check_threads).
template <typename F>
void for_blocks(std::size_t n, int threads, F&& body) {
  const IeeeScope ieee;  // this thread; for_each_block hands it to its tasks (fp_env.h)
  if (threads == 1) return body(std::size_t(0), n);
  auto run = [&] { for_each_block(n, 4096, body); };
  if (threads > 1) return tbb::task_arena(threads).execute(run);
  run();
}

}  // namespace bsprt::api
