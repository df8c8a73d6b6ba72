#pragma once
// Helpers of the stiff-case, watertightness and regression tests: build kd,
// BSP (float and certified leaves, without and with a box top) once per scene, trace ray sets with every
// mode, compare with the exact reference, and optionally append the figures
// to a Markdown table (BSPRT_ROBUSTNESS_REPORT=path) for docs/robustness.md.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "builder/accel_factory.h"
#include "builder/bsp_build.h"
#include "builder/bsp_flatten.h"
#include "geometry/hit_compare.h"
#include "geometry/ray.h"
#include "geometry/triangle_soup.h"
#include "robust/certified_intersector.h"
#include "traverse/bsp_traverse.h"

namespace bsprt::test {

/// A BSP tracer with exact-decision leaves (what --accel bsp-certified makes),
/// sharing a flat tree built once with the float-leaf tracer.
class CertifiedBsp final : public Tracer {
 public:
  /// top_slots > 0: under a box top of subtrees of at most that many slots.
  CertifiedBsp(FlatBspTree flat, const TriangleSoup& soup, std::uint32_t top_slots = 0)
      : exact_(soup), bsp_(std::move(flat), soup) {
    bsp_.set_exact_leaf(&exact_);
    if (top_slots > 0) add_box_top(bsp_, top_slots);
  }
  std::string name() const override { return bsp_.name(); }
  Hit trace(const Ray& ray, RayCounters* c = nullptr) const override { return bsp_.trace(ray, c); }

 private:
  CertifiedIntersector exact_;
  BspTracer bsp_;
};

/// Every tracer of one scene; `soup` must outlive it.
struct ModeSet {
  /// kd, bsp, bsp-certified, bsp-top and bsp-top-certified (box tops over
  /// 8-slot subtrees: many boxes even on small scenes) (+ embree when asked)
  std::vector<std::unique_ptr<Tracer>> modes;
  std::unique_ptr<Tracer> exact;

  ModeSet(const TriangleSoup& soup, bool with_embree, bool with_exact = true) {
    modes.push_back(make_tracer("kd", soup));
    BspConfig config;
    config.threads = 1;
    const FlatBspTree flat = flatten_bsp(soup, build_bsp(soup, config));
    modes.push_back(make_bsp_tracer(soup, flat, BspEpsilon::Certified));
    modes.push_back(std::make_unique<CertifiedBsp>(flat, soup));
    auto top = std::make_unique<BspTracer>(flat, soup);
    add_box_top(*top, 8);
    modes.push_back(std::move(top));
    modes.push_back(std::make_unique<CertifiedBsp>(flat, soup, 8));
    if (with_embree) modes.push_back(make_tracer("embree", soup));
    if (std::getenv("BSPRT_STIFF_BRUTE")) modes.push_back(make_tracer("brute-certified", soup));
    if (with_exact) exact = make_tracer("exact", soup);
  }
};

/// Traces `rays` with `t` (in parallel over TBB).
inline std::vector<Hit> trace_all(const Tracer& t, const std::vector<Ray>& rays) {
  std::vector<Hit> hits(rays.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 256), [&](const auto& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i) hits[i] = t.trace(rays[i]);
  });
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
