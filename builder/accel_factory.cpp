/// \file accel_factory.cpp
/// make_tracer: one switch from `--accel` names to tracers.
#include "builder/accel_factory.h"

#include <oneapi/tbb/task_arena.h>

#include "builder/bsp_build.h"
#include "builder/bsp_file.h"
#include "builder/bsp_flat_io.h"
#include "builder/bsp_flatten.h"
#include "builder/kd_build.h"
#include "builder/tree_file.h"
#include "builder/kd_file.h"
#include "geometry/error.h"
#include "robust/certified_intersector.h"
#include "robust/exact_tracer.h"
#include "traverse/brute_force.h"
#include "traverse/embree_tracer.h"
#include "traverse/bsp_traverse.h"
#include "traverse/kd_traverse.h"

namespace bsprt {
namespace {

/// Runs f on `threads` threads (0 = all).
template <typename F>
auto with_threads(int threads, F&& f) {
  if (threads <= 0) return f();
  tbb::task_arena arena(threads);
  return arena.execute(std::forward<F>(f));
}

std::unique_ptr<Tracer> make_kd(const TriangleSoup& soup, const AccelOptions& options) {
  KdTree tree = options.tree_path.empty()
                    ? with_threads(options.threads, [&] { return build_kd(soup); })
                    : read_kd_tree(options.tree_path, soup);
  return std::make_unique<KdTracer>(std::move(tree), soup);
}

/// A BSP tracer whose leaves use the exact-decision test (owns that test).
class CertifiedBspTracer final : public Tracer {
 public:
  /// top_slots > 0: under a box top of subtrees of at most that many slots.
  CertifiedBspTracer(FlatBspTree flat, const TriangleSoup& soup, std::uint32_t top_slots = 0)
      : exact_(soup), bsp_(std::move(flat), soup, BspEpsilon::Certified) {
    bsp_.set_exact_leaf(&exact_);
    if (top_slots > 0) add_box_top(bsp_, top_slots);
  }
  std::string name() const override { return bsp_.name(); }
  Hit trace(const Ray& ray, RayCounters* counters) const override { return bsp_.trace(ray, counters); }
  std::size_t memory_bytes() const override { return bsp_.memory_bytes(); }

 private:
  CertifiedIntersector exact_;
  BspTracer bsp_;
};

/// The flat BSP tree: read from the file (its flat sections, or flattened from
/// its exact sections), or built and flattened in memory.
FlatBspTree load_or_build_bsp(const TriangleSoup& soup, const AccelOptions& options) {
  if (!options.tree_path.empty()) {
    const TreeFileReader file(options.tree_path);
    if (file.kind() != TreeKind::Bsp)
      throw InputError(options.tree_path, "is a kd-tree file; --accel bsp needs a BSP tree (bsprt build --accel bsp)");
    file.check_scene(soup);
    if (has_flat_bsp_sections(file)) return read_flat_bsp_sections(file, soup);
    const BspTree exact = read_bsp_sections(file, soup);
    try {
      return flatten_bsp(soup, exact);
    } catch (const std::logic_error& e) {  // UsageError and BspTree's own checks: a tree that reads but is
      // inconsistent (a plane that does not cut its cell, ...) is bad input, not a bug.
      // Regression test "tree file: a BSP plane that does not cut its cell is an InputError".
      throw InputError(options.tree_path, std::string("is not a valid BSP tree for this scene: ") + e.what());
    }
  }
  BspConfig config = options.bsp;
  if (options.threads > 0) config.threads = options.threads;
  const BspTree exact = build_bsp(soup, config, nullptr, options.progress);
  return flatten_bsp(soup, exact);
}

}  // namespace

std::vector<std::string> accel_names() { return {"brute", "brute-certified", "exact", "embree", "embree-fast", "kd", "bsp", "bsp-certified", "bsp-zero-eps", "bsp-top", "bsp-top-certified"}; }

std::unique_ptr<Tracer> make_tracer(const std::string& accel, const TriangleSoup& soup,
                                    const AccelOptions& options) {
  if (!options.tree_path.empty() && accel != "kd" && accel.rfind("bsp", 0) != 0)
    throw UsageError("--tree works with --accel kd or bsp, not '" + accel + "'");
  if (accel == "brute") return std::make_unique<BruteForceTracer>(soup);
  if (accel == "exact") return std::make_unique<ExactTracer>(soup);
  if (accel == "brute-certified") return std::make_unique<CertifiedBruteTracer>(soup);
  if (accel == "embree") return std::make_unique<EmbreeTracer>(soup, EmbreeConfig{});
  if (accel == "embree-fast") {
    EmbreeConfig c;
    c.robust = false;
    return std::make_unique<EmbreeTracer>(soup, c);
  }
  if (accel == "kd") return make_kd(soup, options);
  if (accel == "bsp" || accel == "bsp-zero-eps") {
    auto bsp = std::make_unique<BspTracer>(load_or_build_bsp(soup, options), soup,
                                           accel == "bsp" ? BspEpsilon::Certified : BspEpsilon::Zero);
    bsp->set_single_rays(options.single_rays);
    return bsp;
  }
  if (accel == "bsp-top") {
    auto bsp = std::make_unique<BspTracer>(load_or_build_bsp(soup, options), soup, BspEpsilon::Certified);
    add_box_top(*bsp, options.top_slots);
    return bsp;
  }
  if (accel == "bsp-top-certified")
    return std::make_unique<CertifiedBspTracer>(load_or_build_bsp(soup, options), soup, options.top_slots);
  if (accel == "bsp-certified") return std::make_unique<CertifiedBspTracer>(load_or_build_bsp(soup, options), soup);
  std::string names;
  for (const std::string& n : accel_names()) names += (names.empty() ? "" : ", ") + n;
  throw UsageError("unknown accelerator '" + accel + "' (expected one of: " + names + ")");
}

}  // namespace bsprt
