// `bsprt trace SCENE RAYS -o HITS`: traces a ray file with any accelerator and
// writes the nearest hits, reporting rays, hits, seconds and Mrays/s.
#include <fmt/core.h>
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <functional>
#include <memory>
#include <vector>

#include "apps/cli_common.h"
#include "apps/progress.h"
#include "builder/bsp/bsp_face_hits.h"
#include "builder/bsp/bsp_file.h"
#include "builder/tree_file.h"
#include "bsprt/error.h"
#include "bsprt/io.h"
#include "geometry/core/fp_env.h"
#include "robust/certified_intersector.h"
#include "robust/inside_query.h"
#include "traverse/embree/embree_tracer.h"
#include "traverse/trace_parallel.h"

namespace bsprt::cli {
namespace {

struct TraceArgs {
  std::string scene, rays, hits;
  TraceOptions trace;
  bool json = false;
  bool stats = false;
  bool face_hits = false;
  bool all_hits = false;  ///< every crossing, exact (robust/certified_intersector.h), to a CSV
  bool occluded = false;  ///< any hit in [tnear, tfar] per ray, to a text file of 0 and 1
  bool accel_given = false, tree_given = false;
  int passes = 1;  ///< timing passes; the fastest counts
};

/// Rays that are not valid (bsprt/ray.h, is_valid): every mode reports them as
/// misses (formats.md). Counted and reported, so that none passes unnoticed.
std::size_t count_invalid(const std::vector<Ray>& rays) {
  return static_cast<std::size_t>(std::count_if(rays.begin(), rays.end(), [](const Ray& r) { return !is_valid(r); }));
}

void note_invalid(std::size_t invalid, const std::string& path) {
  if (invalid > 0)
    fmt::print("note: {} rays of {} are not valid (a NaN or infinite origin or direction, a zero direction, or NaN "
               "or tnear > tfar bounds) and are reported as misses\n", invalid, path);
}

/// --all-hits: every crossing of every ray, exactly, with simulation of
/// simplicity, from the exact reference's candidates: one line per crossing,
/// "ray,prim,t,side", ordered by ray, then t, then triangle.
void run_all_hits(const TraceArgs& a) {
  if (a.accel_given || a.tree_given)
    throw UsageError("--all-hits is decided exactly from the exact reference's AABB tree; drop --accel and --tree");
  const TriangleSoup soup = load_scene(a.scene, a.trace.allow_nonfinite, !a.json);
  const std::vector<Ray> rays = read_rays(a.rays);
  const std::size_t invalid = count_invalid(rays);
  const auto t0 = std::chrono::steady_clock::now();
  const InsideQuery query(soup);
  std::vector<std::vector<CertifiedIntersector::Crossing>> per_ray(rays.size());
  tbb::combinable<RayCounters> counters;
  IeeeTasks ieee;  // IEEE arithmetic in every task (geometry/core/fp_env.h)
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 256), [&](const auto& r) {
    std::vector<std::uint32_t> candidates;
    for (std::size_t i = r.begin(); i < r.end(); ++i) query.crossings(rays[i], candidates, per_ray[i], &counters.local());
  }, ieee.context());
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ofstream out(a.hits);
  if (!out) throw InputError(a.hits, "cannot write");
  out << "ray,prim,t,side\n";
  std::size_t total = 0;
  for (std::size_t i = 0; i < rays.size(); ++i)
    for (const auto& x : per_ray[i]) {
      out << fmt::format("{},{},{},{}\n", i, x.prim, x.t, x.side);
      ++total;
    }
  if (!out) throw InputError(a.hits, "write failed");
  const RayCounters c = counters.combine([](RayCounters x, const RayCounters& y) { return x += y; });
  if (a.json) {
    fmt::print("{{\"all_hits\": true, \"rays\": {}, \"invalid_rays\": {}, \"crossings\": {}, \"seconds\": {:.6f}, "
               "\"exact_decisions_per_ray\": {:.6f}}}\n",
               rays.size(), invalid, total, s, rays.empty() ? 0.0 : double(c.exact_decisions) / double(rays.size()));
    return;
  }
  note_invalid(invalid, a.rays);
  fmt::print("all hits: {} rays, {} crossings ({:.3f} per ray), {:.3f} s, {:.4f} exact decisions per ray; wrote {}\n",
             rays.size(), total, rays.empty() ? 0.0 : double(total) / double(rays.size()), s,
             rays.empty() ? 0.0 : double(c.exact_decisions) / double(rays.size()), a.hits);
}

/// --face-hits: how many nearest hits a face-plane split proves
/// (builder/bsp_face_hits.h, docs/certified-epsilons.md §8).
struct FaceHitFigures {
  FaceProofStats tree;
  std::uint64_t proven = 0;
};

/// Checked before any ray is traced.
void check_face_hits_usage(const TraceArgs& a) {
  if (a.trace.tree.empty() || TreeFileReader(a.trace.tree).kind() != TreeKind::Bsp)
    throw UsageError("--face-hits needs --tree with a BSP tree file (bsprt build --accel bsp)");
}

FaceHitFigures count_face_hits(const TraceArgs& a, const TriangleSoup& soup, const std::vector<Hit>& hits) {
  const BspTree exact = read_bsp_file(a.trace.tree, soup);
  const FaceHitLocator locator(exact, soup);
  tbb::combinable<std::uint64_t> proven(0);
  IeeeTasks ieee;  // IEEE arithmetic in every task (geometry/core/fp_env.h)
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, hits.size(), 4096), [&](const auto& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i)
      proven.local() += locator.proving_node(hits[i]) != FaceHitLocator::kNone;
  }, ieee.context());
  return {locator.stats(), proven.combine(std::plus<>())};
}

/// Traces all rays in parallel blocks; returns the summed counters.
RayCounters trace_all(const Accelerator& tracer, const std::vector<Ray>& rays, std::vector<Hit>& hits,
                      int packets, bool count) {
  ProgressBar bar("tracing", rays.size(), "rays", ProgressBar::stderr_is_terminal() && rays.size() > (1u << 20));
  ParallelTrace o;
  o.packet_width = packets;
  o.count = count;
  o.on_block = [&bar](std::size_t n) { bar.advance(n); };
  const RayCounters c = trace_parallel(tracer, rays, hits, o);
  bar.finish();
  return c;
}

/// --occluded with single rays: the tracer's any-hit query (occluded), in
/// parallel blocks; occ[i] = 1 when ray i hits something. Returns the summed
/// counters when `count`.
RayCounters occlude_all(const Accelerator& tracer, const std::vector<Ray>& rays, std::vector<std::uint8_t>& occ,
                        bool count) {
  tbb::combinable<RayCounters> local;
  IeeeTasks ieee;  // IEEE arithmetic in every task (geometry/core/fp_env.h)
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 1024), [&](const auto& r) {
    RayCounters* c = count ? &local.local() : nullptr;
    for (std::size_t i = r.begin(); i < r.end(); ++i) occ[i] = tracer.occluded(rays[i], c) ? 1 : 0;
  }, ieee.context());
  return local.combine([](RayCounters x, const RayCounters& y) { return x += y; });
}

void run(const TraceArgs& a) {
  const auto threads = limit_threads(a.trace.threads);
  if (a.all_hits && (a.occluded || a.face_hits || a.stats))
    throw UsageError("--all-hits writes crossings; it does not combine with --occluded, --face-hits or --stats");
  if (a.all_hits) return run_all_hits(a);
  if (a.occluded && a.face_hits) throw UsageError("--occluded does not combine with --face-hits");
  if (a.face_hits) check_face_hits_usage(a);
  const TriangleSoup soup = load_scene(a.scene, a.trace.allow_nonfinite, !a.json);
  const std::vector<Ray> rays = read_rays(a.rays);
  const std::size_t invalid = count_invalid(rays);
  if (accel_info(a.trace.accel).embree_domain)  // the file's own ray numbers, before the build
    for (std::size_t i = 0; i < rays.size(); ++i)
      if (const char* why = embree_cannot_trace(rays[i]))
        throw UsageError(a.rays + ": ray " + std::to_string(i) + " has " + why + "; trace it with kd, bsp, brute or exact");
  const auto t0 = std::chrono::steady_clock::now();
  const std::unique_ptr<Accelerator> tracer = make_accel(a.trace, soup);
  const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // The timed region holds the traversal only: rays checked and the output
  // written before it (std::vector zero-fills, so every page is touched), no
  // counters; the fastest of --passes counts. --stats counts in a pass of its own.
  // --occluded with single rays asks the tracer's any-hit query (occluded);
  // with packets, the nearest hit decides. Both are exact with a certified accelerator.
  const bool any_hit = a.occluded && a.trace.packets <= 1;
  std::vector<Hit> hits(any_hit ? 0 : rays.size());
  std::vector<std::uint8_t> occ(any_hit ? rays.size() : 0);
  double trace_s = 1e300;
  for (int pass = 0; pass < a.passes; ++pass) {
    const auto t1 = std::chrono::steady_clock::now();
    if (any_hit)
      occlude_all(*tracer, rays, occ, false);
    else
      trace_all(*tracer, rays, hits, a.trace.packets, false);
    trace_s = std::min(trace_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
  }
  RayCounters c;
  if (a.stats) c = any_hit ? occlude_all(*tracer, rays, occ, true) : trace_all(*tracer, rays, hits, a.trace.packets, true);
  std::size_t nhit = 0;
  if (a.occluded) {  // any hit in [tnear, tfar], 0 or 1 per ray
    std::ofstream out(a.hits);
    if (!out) throw InputError(a.hits, "cannot write");
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const bool h = any_hit ? occ[i] != 0 : hits[i].hit();
      nhit += h ? 1 : 0;
      out << (h ? "1\n" : "0\n");
    }
    if (!out) throw InputError(a.hits, "write failed");
  } else {
    write_hits(a.hits, hits);
    for (const Hit& h : hits) nhit += h.hit();
  }
  const FaceHitFigures face = a.face_hits ? count_face_hits(a, soup, hits) : FaceHitFigures{};

  const double mrays = trace_s > 0 ? double(rays.size()) / trace_s * 1e-6 : 0.0;
  const double n = rays.empty() ? 1.0 : double(rays.size());
  if (a.json) {
    fmt::print("{{\"accel\": \"{}\", \"rays\": {}, \"invalid_rays\": {}, \"hits\": {}, \"build_seconds\": {:.6f}, "
               "\"trace_seconds\": {:.6f}, \"mrays_per_second\": {:.4f}, \"packets\": {}",
               a.trace.accel, rays.size(), invalid, nhit, build_s, trace_s, mrays, a.trace.packets);
    if (a.stats)
      fmt::print(", \"per_ray\": {{\"kd_node_visits\": {:.4f}, \"bsp_node_visits\": {:.4f}, "
                 "\"leaf_visits\": {:.4f}, \"triangle_tests\": {:.4f}, \"box_node_visits\": {:.4f}, "
                 "\"rule_decisions\": {:.6f}, \"exact_decisions\": {:.6f}, \"exact_rays\": {:.6f}}}",
                 c.kd_node_visits / n, c.bsp_node_visits / n, c.leaf_visits / n, c.triangle_tests / n,
                 c.box_node_visits / n, c.rule_decisions / n, c.exact_decisions / n, c.exact_rays / n);
    if (a.face_hits)
      fmt::print(", \"face_hits\": {{\"proven_hits\": {}, \"face_nodes\": {}, \"proving_nodes\": {}, "
                 "\"inner_nodes\": {}, \"seconds\": {:.3f}}}",
                 face.proven, face.tree.face_nodes, face.tree.proving_nodes, face.tree.inner_nodes,
                 face.tree.seconds);
    fmt::print("}}\n");
    return;
  }
  fmt::print("accel {}: {} rays, {} hits, build {:.3f} s, trace {:.3f} s, {:.2f} Mrays/s\n", a.trace.accel,
             rays.size(), nhit, build_s, trace_s, mrays);
  note_invalid(invalid, a.rays);
  if (a.stats)
    fmt::print("per ray: {:.3f} kd node visits, {:.3f} BSP node visits, {:.3f} leaf visits, {:.3f} triangle tests{}\n",
               c.kd_node_visits / n, c.bsp_node_visits / n, c.leaf_visits / n, c.triangle_tests / n,
               c.box_node_visits ? fmt::format(", {:.3f} box node visits", c.box_node_visits / n) : "");
  if (a.stats && accel_info(a.trace.accel).certified)
    fmt::print("exact leaf decisions per ray: {:.5f} by a rule on exact zeros, {:.5f} in exact arithmetic; "
               "{} of {} rays ({:.4f} %) reached exact arithmetic\n",
               c.rule_decisions / n, c.exact_decisions / n, c.exact_rays, rays.size(), 100.0 * c.exact_rays / n);
  if (a.face_hits) {
    fmt::print("face planes: {} of {} inner nodes split by a triangle's own face plane, {} with the cross-section "
               "inside that triangle (exact, {:.2f} s)\n",
               face.tree.face_nodes, face.tree.inner_nodes, face.tree.proving_nodes, face.tree.seconds);
    fmt::print("face hits: {} of {} hits ({:.2f} %, {:.4f} per ray) lie on such a cross-section: the traversal "
               "could report them from the plane's t\n",
               face.proven, nhit, nhit ? 100.0 * double(face.proven) / double(nhit) : 0.0, double(face.proven) / n);
  }
}

}  // namespace

void register_trace(CLI::App& app) {
  auto args = std::make_shared<TraceArgs>();
  CLI::App* cmd = app.add_subcommand("trace", "trace a .rays file and write the nearest hits to a .hits file");
  cmd->add_option("SCENE", args->scene, kSceneHelp)->required();
  cmd->add_option("RAYS", args->rays, ".rays file (see `bsprt gen-rays`)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->hits, ".hits file to write")->required()->check(output_file());
  add_trace_options(*cmd, args->trace, "bsp");
  cmd->add_flag("--all-hits", args->all_hits,
                "write every crossing of every ray, exactly (simulation of simplicity: a ray through a shared edge "
                "or vertex crosses one triangle of each sheet), as CSV ray,prim,t,side, instead of a .hits file");
  cmd->add_flag("--occluded", args->occluded,
                "write 1 (a hit in [tnear, tfar]) or 0 per ray, as text, instead of a .hits file");
  cmd->add_flag("--json", args->json, "print one JSON object instead of text");
  cmd->add_flag("--stats", args->stats, "count and print node visits and triangle tests per ray");
  cmd->add_option("--passes", args->passes, "timing passes over the rays; the fastest is reported (hits are the same each pass)")
      ->capture_default_str()->check(integer_in(1, 1000));
  cmd->add_flag("--face-hits", args->face_hits,
                "bsp: count hits that a split on the hit triangle's own face plane proves (needs --tree)");
  cmd->callback([args, cmd] {
    if (args->all_hits)  // exact crossings from the exact reference: no accelerator, one untimed pass
      reject_given(*cmd, {"--packets", "--passes", "--single-rays", "--membership", "--top-slots"},
                   "not used by --all-hits, which decides every crossing exactly from the exact reference's tree");
    args->accel_given = cmd->count("--accel") > 0;
    args->tree_given = cmd->count("--tree") > 0;
    run(*args);
  });
}

}  // namespace bsprt::cli
