#pragma once
/// \file accel_factory.h
/// Makes a Tracer by `--accel` name, so the CLI, tests and benchmarks share one
/// switch: brute, brute-certified, exact, embree, embree-fast, kd, bsp,
/// bsp-certified, bsp-zero-eps.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "builder/bsp_config.h"

#include "geometry/triangle_soup.h"
#include "traverse/bsp_traverse.h"
#include "traverse/tracer.h"

namespace bsprt {

/// Options for building an accelerator in memory or loading one from a file.
struct AccelOptions {
  std::string tree_path;  ///< load this tree file instead of building (kd, bsp)
  int threads = 0;        ///< 0 = all cores
  /// Called with (done, total) during long builds (the CLI draws a bar).
  std::function<void(double, double)> progress;
  BspConfig bsp;          ///< settings of an in-memory BSP build
  /// bsp-top, bsp-top-certified: largest BSP subtree (in 8-byte slots) under
  /// one box of the box top (traverse/bsp_boxtop.h).
  std::uint32_t top_slots = 1024;
  /// bsp, bsp-zero-eps: how batches of single rays run (traverse/bsp_traverse.h).
  BspSingleRays single_rays = BspSingleRays::Auto;
};

/// Accelerator names `make_tracer` accepts.
std::vector<std::string> accel_names();

/// Builds (or loads) the named accelerator over `soup`, which must outlive it.
/// Throws UsageError for an unknown name, InputError for a bad tree file.
std::unique_ptr<Tracer> make_tracer(const std::string& accel, const TriangleSoup& soup,
                                    const AccelOptions& options = {});

}  // namespace bsprt
