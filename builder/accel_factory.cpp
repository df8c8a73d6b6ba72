/// \file accel_factory.cpp
/// make_tracer: one switch from `--accel` names to tracers.
#include "builder/accel_factory.h"

#include "builder/bsp/bsp_build.h"
#include "builder/bsp/bsp_file.h"
#include "builder/bsp/bsp_flat_io.h"
#include "builder/bsp/bsp_flatten.h"
#include "builder/kd/kd_build.h"
#include "builder/tree_file.h"
#include "builder/kd/kd_file.h"
#include "bsprt/error.h"
#include "geometry/core/fp_env.h"
#include "robust/certified_intersector.h"
#include "robust/exact_tracer.h"
#include "traverse/brute_force.h"
#include "traverse/embree/embree_tracer.h"
#include "traverse/bsp/bsp_traverse.h"
#include "traverse/embree/box_top_build.h"
#include "traverse/embree/bvh8_build.h"
#include "traverse/bvh/bvh8_traverse.h"
#include "traverse/kd/kd_traverse.h"

namespace bsprt {
namespace {

/// The tree file of `options` (in memory, or opened from tree_path), or null.
std::shared_ptr<const TreeFileReader> tree_file_of(const AccelOptions& options) {
  if (options.tree_file) return options.tree_file;
  if (!options.tree_path.empty()) return std::make_shared<const TreeFileReader>(options.tree_path);
  return nullptr;
}

KdTree load_or_build_kd(const TriangleSoup& soup, const AccelOptions& options) {
  const auto file = tree_file_of(options);
  return file ? read_kd_tree(*file, soup) : build_kd(soup);
}

std::unique_ptr<Accelerator> make_kd_float(const TriangleSoup& soup, const AccelOptions& options) {
  return std::make_unique<KdTracer>(load_or_build_kd(soup, options), soup);
}

/// A tracer (KdTracer, BspTracer, Bvh8Tracer) whose leaves use the
/// exact-decision test, which it owns; `tracer()` finishes the setup.
template <typename Tracer>
class ExactLeafTracer final : public Accelerator {
 public:
  template <typename... Args>
  explicit ExactLeafTracer(const TriangleSoup& soup, Args&&... args)
      : exact_(soup), tracer_(std::forward<Args>(args)...) {
    tracer_.set_exact_leaf(&exact_);
  }
  Tracer& tracer() { return tracer_; }
  std::string name() const override { return tracer_.name(); }
  Hit trace(const Ray& ray, RayCounters* counters) const override { return tracer_.trace(ray, counters); }
  bool occluded(const Ray& ray, RayCounters* counters) const override { return tracer_.occluded(ray, counters); }
  void trace_batch(std::span<const Ray> rays, std::span<Hit> hits, int packet_width,
                   RayCounters* counters) const override {
    tracer_.trace_batch(rays, hits, packet_width, counters);
  }
  std::size_t memory_bytes() const override { return tracer_.memory_bytes(); }

 private:
  CertifiedIntersector exact_;  // before tracer_: constructed first, destroyed last
  Tracer tracer_;
};

/// Which top a BSP mode puts over its tree.
enum class BspTop { None, Box4, Bvh8 };

/// `slots` 0 takes the top's default (AccelOptions::top_slots): the largest
/// subtree that measured fastest on bunny random rays (cachegrind, docs/bvh8.md).
void add_top(BspTracer& t, BspTop top, std::uint32_t slots) {
  if (top == BspTop::Box4) add_box_top(t, slots ? slots : 1024);
  if (top == BspTop::Bvh8) add_bvh8_top(t, slots ? slots : 1);
}

/// bsp, bsp-top or bsp-bvh8: the BSP with exact leaves, under `top` of subtrees of at most `slots` slots.
std::unique_ptr<Accelerator> make_exact_bsp(const TriangleSoup& soup, FlatBspTree flat, BspTop top,
                                            std::uint32_t slots, BspSingleRays single_rays,
                                            BspPackets packets = BspPackets::Auto) {
  auto t = std::make_unique<ExactLeafTracer<BspTracer>>(soup, std::move(flat), soup, BspEpsilon::Certified);
  t->tracer().set_single_rays(single_rays);
  t->tracer().set_packets(packets);
  add_top(t->tracer(), top, slots);
  return t;
}

/// The flat BSP tree: read from the file (its flat sections, or flattened from
/// its exact sections), or built and flattened in memory.
FlatBspTree load_or_build_bsp(const TriangleSoup& soup, const AccelOptions& options) {
  if (const auto file_ptr = tree_file_of(options)) {
    const TreeFileReader& file = *file_ptr;
    if (file.kind() != TreeKind::Bsp)
      throw InputError(file.path(), "is a kd-tree file; --accel bsp needs a BSP tree (bsprt build --accel bsp)");
    file.check_scene(soup);
    if (has_flat_bsp_sections(file)) return read_flat_bsp_sections(file, soup);
    const BspTree exact = read_bsp_sections(file, soup);
    try {
      return flatten_bsp(soup, exact);
    } catch (const std::logic_error& e) {  // UsageError and BspTree's own checks: a tree that reads but is
      // inconsistent (a plane that does not cut its cell, ...) is bad input, not a bug.
      // Regression test "tree file: a BSP plane that does not cut its cell is an InputError".
      throw InputError(file.path(), std::string("is not a valid BSP tree for this scene: ") + e.what());
    }
  }
  BspConfig config = options.bsp;
  if (options.threads > 0) config.threads = options.threads;
  const BspTree exact = build_bsp(soup, config, nullptr, options.progress);
  return flatten_bsp(soup, exact);
}

std::unique_ptr<Accelerator> make_bsp(const TriangleSoup& soup, const AccelOptions& options,
                                      BspEpsilon eps) {
  auto bsp = std::make_unique<BspTracer>(load_or_build_bsp(soup, options), soup, eps);
  bsp->set_single_rays(options.single_rays);
  bsp->set_packets(options.bsp_packets);
  return bsp;
}

std::unique_ptr<Accelerator> make_embree(const TriangleSoup& soup, bool robust) {
  EmbreeConfig c;
  c.robust = robust;
  return std::make_unique<EmbreeTracer>(soup, c);
}

using A = AccelTree;
// name, what, tree, certified, packets, slow, embree_domain, single_rays, top_slots, make
constexpr AccelInfo kTable[] = {
    {"brute", "every triangle, float watertight test", A::None, false, true, true, false, false, false,
     [](const TriangleSoup& s, const AccelOptions&) -> std::unique_ptr<Accelerator> {
       return std::make_unique<BruteForceTracer>(s);
     }},
    {"brute-certified", "every triangle, exact-decision test", A::None, true, false, true, false, false, false,
     [](const TriangleSoup& s, const AccelOptions&) -> std::unique_ptr<Accelerator> {
       return std::make_unique<CertifiedBruteTracer>(s);
     }},
    {"exact", "the exact reference: CGAL AABB tree, exact predicates and parameters", A::None, true, false, true,
     false, false, false,
     [](const TriangleSoup& s, const AccelOptions&) -> std::unique_ptr<Accelerator> {
       return std::make_unique<ExactTracer>(s);
     }},
    {"embree", "Embree 3, robust mode", A::None, false, true, false, true, false, false,
     [](const TriangleSoup& s, const AccelOptions&) { return make_embree(s, true); }},
    {"embree-fast", "Embree 3, default mode", A::None, false, true, false, true, false, false,
     [](const TriangleSoup& s, const AccelOptions&) { return make_embree(s, false); }},
    {"kd", "SAH kd-tree, conservative traversal, exact-decision leaf test (the default)", A::Kd, true, true, false,
     false, false, false,
     [](const TriangleSoup& s, const AccelOptions& o) -> std::unique_ptr<Accelerator> {
       return std::make_unique<ExactLeafTracer<KdTracer>>(s, load_or_build_kd(s, o), s);
     }},
    {"kd-float", "SAH kd-tree, float watertight leaf test", A::Kd, false, true, false, false, false, false,
     make_kd_float},
    {"bsp", "exact BSP, certified traversal, exact-decision leaf test (the default)", A::Bsp, true, true, false,
     false, true, false,
     [](const TriangleSoup& s, const AccelOptions& o) -> std::unique_ptr<Accelerator> {
       return make_exact_bsp(s, load_or_build_bsp(s, o), BspTop::None, 0, o.single_rays, o.bsp_packets);
     }},
    {"bsp-float", "exact BSP, certified float traversal, float watertight leaf test", A::Bsp, false, true, false,
     false, true, false,
     [](const TriangleSoup& s, const AccelOptions& o) { return make_bsp(s, o, BspEpsilon::Certified); }},
    {"bsp-zero-eps", "exact BSP traversed without the certified epsilons", A::Bsp, false, true, false, false, true,
     false, [](const TriangleSoup& s, const AccelOptions& o) { return make_bsp(s, o, BspEpsilon::Zero); }},
    {"bsp-top-float", "bsp-top with the float watertight leaf test", A::Bsp, false, false, false, false, false, true,
     [](const TriangleSoup& s, const AccelOptions& o) -> std::unique_ptr<Accelerator> {
       auto bsp = std::make_unique<BspTracer>(load_or_build_bsp(s, o), s, BspEpsilon::Certified);
       add_top(*bsp, BspTop::Box4, o.top_slots);
       return bsp;
     }},
    {"bsp-bvh8", "the BSP under an 8-wide BVH over its pieces (the bvh8 kernel), single rays, exact-decision leaf test",
     A::Bsp, true, false, false, false, false, true,
     [](const TriangleSoup& s, const AccelOptions& o) -> std::unique_ptr<Accelerator> {
       return make_exact_bsp(s, load_or_build_bsp(s, o), BspTop::Bvh8, o.top_slots, BspSingleRays::Auto);
     }},
    {"bsp-bvh8-float", "bsp-bvh8 with the float watertight leaf test", A::Bsp, false, false, false, false, false, true,
     [](const TriangleSoup& s, const AccelOptions& o) -> std::unique_ptr<Accelerator> {
       auto bsp = std::make_unique<BspTracer>(load_or_build_bsp(s, o), s, BspEpsilon::Certified);
       add_top(*bsp, BspTop::Bvh8, o.top_slots);
       return bsp;
     }},
    {"bsp-top", "the BSP under a 4-wide box top, single rays, exact-decision leaf test", A::Bsp, true, false, false,
     false, false, true,
     [](const TriangleSoup& s, const AccelOptions& o) -> std::unique_ptr<Accelerator> {
       return make_exact_bsp(s, load_or_build_bsp(s, o), BspTop::Box4, o.top_slots, BspSingleRays::Auto);
     }},
    {"bvh8", "plain 8-wide BVH (Embree's SAH builder), Embree-style single-ray kernel, exact-decision leaf test",
     A::None, true, false, false, false, false, false,
     [](const TriangleSoup& s, const AccelOptions& o) -> std::unique_ptr<Accelerator> {
       return std::make_unique<ExactLeafTracer<Bvh8Tracer>>(s, build_bvh8(s));
     }},
    {"bvh8-float", "plain 8-wide BVH, Embree-style single-ray kernel, float watertight leaf test", A::None, false,
     false, false, false, false, false,
     [](const TriangleSoup& s, const AccelOptions& o) -> std::unique_ptr<Accelerator> {
       return std::make_unique<Bvh8Tracer>(build_bvh8(s));
     }},
};

}  // namespace

std::span<const AccelInfo> accel_table() { return kTable; }

const AccelInfo& accel_info(std::string_view name) {
  for (const AccelInfo& a : kTable)
    if (a.name == name) return a;
  // The names before exact leaves became the default (issue #23).
  if (name == "bsp-certified" || name == "bsp-top-certified")
    throw UsageError("accelerator '" + std::string(name) + "' is now '" + (name == "bsp-certified" ? "bsp" : "bsp-top") +
                     "' (exact leaf decisions are the default; the float leaf test is '" +
                     (name == "bsp-certified" ? "bsp-float" : "bsp-top-float") + "')");
  std::string names;
  for (const AccelInfo& a : kTable) names += (names.empty() ? "" : ", ") + std::string(a.name);
  throw UsageError("unknown accelerator '" + std::string(name) + "' (expected one of: " + names + ")");
}

std::vector<std::string> accel_names() {
  std::vector<std::string> names;
  for (const AccelInfo& a : kTable) names.emplace_back(a.name);
  return names;
}

std::unique_ptr<Accelerator> make_tracer(const std::string& accel, const TriangleSoup& soup,
                                         const AccelOptions& options) {
  const AccelInfo& info = accel_info(accel);
  check_threads(options.threads, "threads");
  if (options.has_tree() && info.tree == AccelTree::None) {
    std::string with_tree;  // every accelerator that reads a kd or BSP tree file
    for (const std::string& name : accel_names())
      if (accel_info(name).tree != AccelTree::None) with_tree += (with_tree.empty() ? "" : ", ") + name;
    throw UsageError("a tree file works with the accelerators " + with_tree + ", not '" + accel + "'");
  }
  // Builds run on options.threads threads (0 = all). Builds, tree checks and exact setup assume
  // IEEE arithmetic, and Embree's scene commit sets FTZ and DAZ while it runs TBB tasks: run in
  // an arena made under an IeeeScope, so that a thread whose first use of TBB is this call gets
  // its implicit arena in IEEE arithmetic too (task_arena::initialize makes it), and later loops
  // of the caller do not inherit FTZ (fp_env.h).
  return run_ieee(options.threads, [&] { return info.make(soup, options); });
}

std::string bsp_tree_load_problem(const TriangleSoup& soup, std::shared_ptr<const TreeFileReader> file) {
  AccelOptions options;
  options.tree_file = std::move(file);
  try {
    make_tracer("bsp-float", soup, options);  // the loader and BspTracer's checks, as `trace --tree` runs them
  } catch (const std::logic_error& e) {        // UsageError, and the trees' own validation
    return e.what();
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

}  // namespace bsprt
