// `bsprt build SCENE -o TREE --accel kd|bsp`: builds a tree and writes it as a
// versioned, checksummed tree file bound to the scene; `bsprt stats TREE`
// prints a tree file's figures.
#include <fmt/core.h>

#include <memory>

#include "apps/cli_common.h"
#include "apps/progress.h"
#include "builder/kd_build.h"
#include "builder/kd_file.h"
#include "builder/tree_file.h"

namespace bsprt::cli {
namespace {

struct BuildArgs {
  std::string scene, output, accel = "kd";
  int threads = 0;
  bool allow_nonfinite = false;
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

void run_build(const BuildArgs& a) {
  const auto threads = limit_threads(a.threads);
  const TriangleSoup soup = load_scene(a.scene, a.allow_nonfinite, true);
  if (a.accel == "kd") return build_kd_file(a, soup);
  throw UsageError("bsprt build: --accel must be kd or bsp, not '" + a.accel + "'");
}

void run_stats(const std::string& path) {
  const TreeFileReader file(path);
  if (file.kind() == TreeKind::Kd) {
    KdTree tree;
    tree.nodes = file.array<KdNode>(kKdNodesTag);
    tree.prims = file.array<std::uint32_t>(kKdPrimsTag);
    const std::vector<float> b = file.array<float>(kKdBoundsTag);
    if (b.size() != 6) throw InputError(path, "bounds section must hold 6 floats");
    tree.bounds = {{b[0], b[1], b[2]}, {b[3], b[4], b[5]}};
    tree.triangle_count = std::uint32_t(file.triangle_count());
    tree.validate();
    fmt::print("{}: kd-tree, ", path);
    print_kd_stats(kd_tree_stats(tree));
    return;
  }
  throw InputError(path, "stats: unsupported tree kind");
}

}  // namespace

void register_build(CLI::App& app) {
  auto args = std::make_shared<BuildArgs>();
  CLI::App* cmd = app.add_subcommand("build", "build a tree and write it to a tree file bound to the scene");
  cmd->add_option("SCENE", args->scene, "mesh file or 'default'")->required();
  cmd->add_option("-o,--output", args->output, "tree file to write")->required();
  cmd->add_option("--accel", args->accel, "kd (SAH kd-tree)")->capture_default_str();
  cmd->add_option("--threads", args->threads, "worker threads (0 = all cores)")->capture_default_str();
  cmd->add_flag("--allow-nonfinite", args->allow_nonfinite, "keep triangles with NaN/Inf corners (flagged degenerate)");
  cmd->callback([args] { run_build(*args); });

  auto path = std::make_shared<std::string>();
  CLI::App* stats = app.add_subcommand("stats", "print the figures of a tree file");
  stats->add_option("TREE", *path, "tree file written by `bsprt build`")->required()->check(CLI::ExistingFile);
  stats->callback([path] { run_stats(*path); });
}

}  // namespace bsprt::cli
