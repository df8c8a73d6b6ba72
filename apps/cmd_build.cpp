// `bsprt build SCENE -o TREE --accel kd|bsp`: builds a tree and writes it as a
// versioned, checksummed tree file bound to the scene; `bsprt stats TREE`
// prints a tree file's figures.
#include <fmt/core.h>
#include <sys/resource.h>

#include <memory>
#include <optional>

#include "apps/cli_common.h"
#include "apps/progress.h"
#include "builder/bsp/bsp_build.h"
#include "builder/bsp/bsp_file.h"
#include "builder/bsp/bsp_flat_io.h"
#include "builder/bsp/bsp_flatten.h"
#include "builder/kd/kd_build.h"
#include "builder/kd/kd_file.h"
#include "builder/tree_file.h"
#include "bsprt/error.h"
#include "traverse/bsp/bsp_node.h"

namespace bsprt::cli {
namespace {

struct BuildArgs {
  std::string scene, output, accel = "bsp", membership = "area";  // bsp: the default everywhere (trace, render, the API)
  int threads = 0;
  bool allow_nonfinite = false;
  bool paper = false;  // the paper's full BSP: face/edge candidates at every node size
  BspConfig costs;     // bsp: SAH constants (--cost-*), defaults of BspConfig
};

void print_kd_stats(const KdTreeStats& s) {
  fmt::print("nodes {}, leaves {} ({} empty), {} triangle references, {:.2f} per non-empty leaf, depth {}, {} bytes\n",
             s.nodes, s.leaves, s.empty_leaves, s.references, s.avg_leaf_size, s.max_depth, s.bytes);
}

void build_kd_file(const BuildArgs& a, const TriangleSoup& soup) {
  KdBuildReport report;
  const KdConfig config;
  const KdTree tree = build_kd(soup, config, &report);
  write_kd_tree(a.output, tree, soup, config);
  fmt::print("built kd-tree in {:.3f} s: ", report.seconds);
  print_kd_stats(kd_tree_stats(tree));
  fmt::print("wrote {}\n", a.output);
}

/// Split counts by depth, leaf sizes: what `bsprt build` and `stats` print for BSP trees.
struct BspFigures {
  std::vector<std::size_t> kd_by_depth, bsp_by_depth, leaf_histogram;
  std::size_t nodes = 0, leaves = 0, refs = 0;
};

BspFigures bsp_figures(const std::vector<BspNode>& nodes, const std::vector<PlaneDef>& planes, const std::string& path) {
  BspFigures f;
  f.nodes = nodes.size();
  std::vector<std::pair<std::uint32_t, std::size_t>> stack{{0, 0}};
  std::size_t visited = 0;
  while (!stack.empty()) {
    const auto [i, depth] = stack.back();
    stack.pop_back();
    if (i >= nodes.size() || ++visited > nodes.size()) throw InputError(path, "BSP nodes do not form a tree");
    const BspNode& n = nodes[i];
    if (n.is_leaf()) {
      ++f.leaves, f.refs += n.b;
      if (f.leaf_histogram.size() <= n.b) f.leaf_histogram.resize(std::size_t(n.b) + 1, 0);
      ++f.leaf_histogram[n.b];
      continue;
    }
    if (n.plane >= planes.size()) throw InputError(path, "BSP node names a plane out of range");
    auto& row = planes[n.plane].kind == PlaneKind::Kd ? f.kd_by_depth : f.bsp_by_depth;
    if (row.size() <= depth) row.resize(depth + 1, 0);
    ++row[depth];
    stack.push_back({n.b, depth + 1});
    stack.push_back({n.a, depth + 1});
  }
  return f;
}

void print_bsp_figures(const BspFigures& f) {
  std::size_t kd = 0, bsp = 0;
  for (std::size_t v : f.kd_by_depth) kd += v;
  for (std::size_t v : f.bsp_by_depth) bsp += v;
  const std::size_t nonempty = f.leaves - (f.leaf_histogram.empty() ? 0 : f.leaf_histogram[0]);
  fmt::print("nodes {}, leaves {} ({} empty), {} kd splits, {} BSP (face/edge) splits, {:.2f} triangles per non-empty leaf\n",
             f.nodes, f.leaves, f.leaves - nonempty, kd, bsp, nonempty ? double(f.refs) / double(nonempty) : 0.0);
  fmt::print("splits by depth (depth: kd/bsp):");
  const std::size_t depth = std::max(f.kd_by_depth.size(), f.bsp_by_depth.size());
  for (std::size_t d = 0; d < depth; ++d)
    fmt::print("{}{}: {}/{}", d % 8 ? "  " : "\n  ", d, d < f.kd_by_depth.size() ? f.kd_by_depth[d] : 0,
               d < f.bsp_by_depth.size() ? f.bsp_by_depth[d] : 0);
  // Every leaf is counted: one bin per count below 16, then bins of doubling
  // width ([16-31], [32-63], ...), and the largest leaf.
  fmt::print("\nleaves by triangle count:");
  const std::size_t bins = f.leaf_histogram.size();
  for (std::size_t n = 0; n < std::min<std::size_t>(bins, 16); ++n)
    if (f.leaf_histogram[n]) fmt::print(" [{}]={}", n, f.leaf_histogram[n]);
  for (std::size_t lo = 16; lo < bins; lo *= 2) {
    std::size_t count = 0;
    for (std::size_t n = lo; n < std::min(bins, 2 * lo); ++n) count += f.leaf_histogram[n];
    if (count) fmt::print(" [{}-{}]={}", lo, 2 * lo - 1, count);
  }
  if (bins > 0) fmt::print("; largest {}", bins - 1);
  fmt::print("\n");
}

void build_bsp_file(const BuildArgs& a, const TriangleSoup& soup) {
  BspConfig config = a.costs;
  config.membership = parse_membership(a.membership);
  config.threads = a.threads;
  if (a.paper) config.bsp_max_triangles = SIZE_MAX;
  BspBuildReport report;
  BspTree tree;
  {
    ProgressBar bar("building bsp", 1000, "permille", ProgressBar::stderr_is_terminal());
    tree = build_bsp(soup, config, &report, [&](double done, double total) {
      bar.set(total > 0 ? std::uint64_t(1000.0 * done / total) : 0);
    });
  }
  FlattenReport flat_report;
  const FlatBspTree flat = flatten_bsp(soup, tree, &flat_report);
  const BspReportRecord record{report.seconds, report.exact.filter_calls, report.exact.symbolic,
                               report.exact.exact_fallbacks, report.exact.exact_points};
  write_bsp_file_with_flat(a.output, soup, tree, flat, &record);
  fmt::print("built BSP tree in {:.3f} s ({:.0f} triangles/s), membership {}, exact fallbacks {} of {} filtered side tests\n",
             report.seconds, double(report.triangles) / std::max(report.seconds, 1e-9), a.membership,
             report.exact.exact_fallbacks, report.exact.filter_calls);
  print_bsp_figures(bsp_figures(tree.nodes(), tree.planes(), a.output));
  const FlatBspStats fs = flat_bsp_stats(flat);
  fmt::print("flat tree: {} nodes ({} plane, {} kd), {} bytes; wrote {}\n", fs.nodes, fs.plane_nodes, fs.kd_nodes,
             fs.bytes, a.output);
}

/// The process's peak resident memory so far (getrusage; Linux reports KiB).
double peak_memory_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;
}

void run_build(const BuildArgs& a) {
  const auto threads = limit_threads(a.threads);
  const TriangleSoup soup = load_scene(a.scene, a.allow_nonfinite, true);
  if (a.accel == "kd") build_kd_file(a, soup);
  else if (a.accel == "bsp") build_bsp_file(a, soup);
  else throw UsageError("bsprt build: --accel must be kd or bsp, not '" + a.accel + "'");
  fmt::print("peak memory {:.0f} MB (the whole run: load, build, write)\n", peak_memory_mb());
}

/// Version 1 files' headers are not covered by their CRC: said, not hidden.
std::string version_note(const TreeFileReader& file) {
  return file.version() == 1 ? " (version 1 file: its header is not covered by the CRC)" : "";
}

void run_stats(const std::string& path) {
  const TreeFileReader file(path);
  if (file.triangle_count() > 0xFFFFFFFFull)
    throw InputError(path, "tree file header names " + std::to_string(file.triangle_count()) + " triangles (at most 2^32 - 1)");
  if (file.kind() == TreeKind::Kd) {
    const KdTree tree = read_kd_sections(file, std::uint32_t(file.triangle_count()));
    fmt::print("{}: kd-tree{}, ", path, version_note(file));
    print_kd_stats(kd_tree_stats(tree));
    return;
  }
  // Every section is read (and checked) before anything is printed.
  const std::optional<BspReportRecord> rec =
      file.has_section(kBspReportTag) ? std::optional(file.record<BspReportRecord>(kBspReportTag)) : std::nullopt;
  const BspFigures figures = bsp_figures(file.array<BspNode>(kBspNodesTag), file.array<PlaneDef>(kBspPlanesTag), path);
  fmt::print("{}: BSP tree for {} triangles{}, ", path, file.triangle_count(), version_note(file));
  if (rec)
    fmt::print("built in {:.3f} s, exact fallbacks {} of {} filtered side tests ({} symbolic), ", rec->seconds,
               rec->exact_fallbacks, rec->filter_calls, rec->symbolic);
  print_bsp_figures(figures);
}

}  // namespace

void register_build(CLI::App& app) {
  auto args = std::make_shared<BuildArgs>();
  CLI::App* cmd = app.add_subcommand("build", "build a tree and write it to a tree file bound to the scene");
  cmd->add_option("SCENE", args->scene, kSceneHelp)->required();
  cmd->add_option("-o,--output", args->output, "tree file to write")->required()->check(output_file());
  cmd->add_option("--accel", args->accel, "kd (SAH kd-tree) or bsp (exact general BSP)")->capture_default_str();
  cmd->add_option("--membership", args->membership, "bsp: area (default) or closed, see docs/bsp-build.md")
      ->capture_default_str();
  cmd->add_flag("--paper", args->paper, "bsp: evaluate face/edge planes at every node (the paper's full, slow build)");
  cmd->add_option("--cost-isect", args->costs.c_isect, "bsp SAH: cost of one triangle test")
      ->capture_default_str()->check(number_above(0.0));
  cmd->add_option("--cost-kd", args->costs.c_kd, "bsp SAH: cost of a kd node")
      ->capture_default_str()->check(number_above(0.0));
  cmd->add_option("--cost-bsp-slope", args->costs.c_bsp_slope,
                  "bsp SAH: C_BSP = slope*C_isect*(N-2) + C_kd where a kd split cuts the node")
      ->capture_default_str()->check(number_at_least(0.0));
  cmd->add_option("--cost-bsp-fixed", args->costs.c_bsp_fixed, "bsp SAH: C_BSP where no kd split cuts the node")
      ->capture_default_str()->check(number_above(0.0));
  cmd->add_option("--empty-bonus", args->costs.empty_bonus,
                  "bsp SAH: cost factor in (0, 1] of a split with an empty child (kd-tree: 0.8; 1 = none)")
      ->capture_default_str()->check(number_above(0.0))->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--min-gain", args->costs.min_gain,
                  "bsp: least expected triangle tests per ray a split must save (docs/bsp-build.md)")
      ->capture_default_str()->check(number_at_least(0.0));
  cmd->add_option("--min-gain-triangles", args->costs.min_gain_triangles,
                  "bsp: --min-gain limits every split of a node of at most this many triangles, in larger nodes only "
                  "splits that keep all of them in one child (docs/bsp-build.md)")
      ->capture_default_str()->check(integer_in(0, 1 << 30));
  cmd->add_flag("--planar-slabs,!--no-planar-slabs", args->costs.planar_slabs,
                "bsp: kd candidates one float step either side of each axis-planar triangle, so a split can keep it "
                "in a thin slab (default on; docs/bsp-build.md)");
  cmd->add_option("--threads", args->threads, "worker threads (0 = all cores)")
      ->check(integer_in(0, kMaxThreads))->capture_default_str();
  cmd->add_flag("--allow-nonfinite", args->allow_nonfinite, "keep triangles with NaN/Inf corners (flagged degenerate)");
  cmd->callback([args] { run_build(*args); });

  auto path = std::make_shared<std::string>();
  CLI::App* stats = app.add_subcommand("stats", "print the figures of a tree file");
  stats->add_option("TREE", *path, "tree file written by `bsprt build`")->required()->check(CLI::ExistingFile);
  stats->callback([path] { run_stats(*path); });
}

}  // namespace bsprt::cli
