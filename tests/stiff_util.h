#pragma once
// Helpers of the stiff-case, watertightness and regression tests: build kd,
// BSP (float and certified leaves, without and with a box top) once per scene, trace ray sets with every
// mode, compare with the exact reference, and optionally append the figures
// to a Markdown table (BSPRT_ROBUSTNESS_REPORT=path) for docs/robustness.md.

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "builder/accel_factory.h"
#include "builder/bsp/bsp_build.h"
#include "builder/bsp/bsp_flat_io.h"
#include "builder/bsp/bsp_flatten.h"
#include "bsprt/compare.h"
#include "bsprt/ray.h"
#include "geometry/core/triangle_soup.h"
#include "traverse/bsp/bsp_traverse.h"
#include "traverse/trace_parallel.h"

namespace bsprt::test {

/// Every tracer of one scene, made from the accelerator table; `soup` must outlive it.
struct ModeSet {
  /// kd-float, kd, bvh8-float, bvh8 and bsp (exact leaves), bsp-float, bsp-top and bsp-top-float, bsp-bvh8 and
  /// bsp-bvh8-float (tops over 8-slot subtrees: many boxes even on small scenes) (+ embree when asked);
  /// the BSP modes share one build, handed to them as an in-memory tree file.
  std::vector<std::unique_ptr<Accelerator>> modes;
  std::unique_ptr<Accelerator> exact;

  ModeSet(const TriangleSoup& soup, bool with_embree, bool with_exact = true) {
    modes.push_back(make_tracer("kd-float", soup));
    modes.push_back(make_tracer("kd", soup));
    modes.push_back(make_tracer("bvh8-float", soup));
    modes.push_back(make_tracer("bvh8", soup));
    BspConfig config;
    config.threads = 1;
    const BspTree tree = build_bsp(soup, config);
    AccelOptions bsp;
    bsp.tree_file = std::make_shared<const TreeFileReader>(
        "(test: in-memory tree)", bsp_tree_file(soup, tree, flatten_bsp(soup, tree)).bytes());
    bsp.top_slots = 8;
    for (const char* mode : {"bsp-float", "bsp", "bsp-top-float", "bsp-top", "bsp-bvh8-float", "bsp-bvh8"})
      modes.push_back(make_tracer(mode, soup, bsp));
    if (with_embree) modes.push_back(make_tracer("embree", soup));
    if (std::getenv("BSPRT_STIFF_BRUTE")) modes.push_back(make_tracer("brute-certified", soup));
    if (with_exact) exact = make_tracer("exact", soup);
  }
};

/// Traces `rays` with `t` (in parallel over TBB).
inline std::vector<Hit> trace_all(const Accelerator& t, const std::vector<Ray>& rays) {
  std::vector<Hit> hits(rays.size());
  ParallelTrace o;
  o.block = 256;
  trace_parallel(t, rays, hits, o);
  return hits;
}

/// Appends one Markdown table row to $BSPRT_ROBUSTNESS_REPORT when it is set.
inline void report_row(const std::string& row) {
  const char* path = std::getenv("BSPRT_ROBUSTNESS_REPORT");
  if (!path || !*path) return;
  if (std::FILE* f = std::fopen(path, "a")) {
    std::fputs((row + "\n").c_str(), f);
    std::fclose(f);
  }
}

}  // namespace bsprt::test
