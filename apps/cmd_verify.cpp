// `bsprt verify SCENE TREE`: the independent exact certificate of a BSP tree
// file (robust/verify.h, docs/verify.md). Exit 0 and "CERTIFIED", or exit 1
// with the first counter-example.
#include <fmt/core.h>

#include <chrono>
#include <memory>
#include <stdexcept>

#include "apps/cli_common.h"
#include "apps/progress.h"
#include "builder/accel_factory.h"
#include "builder/kd/kd_build.h"
#include "builder/kd/kd_file.h"
#include "builder/tree_file.h"
#include "verify/verify_file.h"
#include "verify/verify.h"

namespace bsprt::cli {
namespace {

struct VerifyArgs {
  std::string scene, tree;
  int threads = 0;
  bool strict = false;
  bool allow_nonfinite = false;
};

void print_report(const VerifyReport& r) {
  fmt::print("rule              {} (coplanar triangles {})\n", r.membership,
             r.coplanar_to_both ? "on both sides" : "on one side");
  fmt::print("nodes checked     {}\n", r.nodes);
  fmt::print("leaves            {}\n", r.leaves);
  fmt::print("triangles         {} ({} degenerate, not listed)\n", r.triangles, r.degenerate_triangles);
  fmt::print("pairs checked     {} triangle-leaf pairs ({} required)\n", r.pairs, r.required_pairs);
  fmt::print("extra listings    {} (listed, not touching: warning)\n", r.extra_listings);
  fmt::print("boundary listings {} (listed, touching with zero area: allowed)\n", r.boundary_listings);
  fmt::print("flat nodes        {} plane (max eps use {:.4f}), {} kd\n", r.flat_plane_nodes, r.max_eps_use,
             r.flat_kd_nodes);
  fmt::print("volume check      |sum leaves - root| / root <= {:.3g}\n", r.volume_rel_error);
  fmt::print("side tests        {} interval, {} exact fallbacks, {} exact points\n", r.filter_tests,
             r.exact_fallbacks, r.exact_points);
  for (const std::string& n : r.notes) fmt::print("note              {}\n", n);
  fmt::print("seconds           {:.2f}\n", r.seconds);
}

/// kd-tree files: the structural check of read_kd_tree, then the exact
/// coverage check (builder/kd_validate.cpp, rationals, independent of the
/// build's clipping): every non-degenerate triangle touching a leaf's closed
/// box is listed there (a triangle lying in a split plane: on one side).
void run_kd(const VerifyArgs& a, const TriangleSoup& soup) {
  const auto start = std::chrono::steady_clock::now();
  const KdTree tree = read_kd_tree(a.tree, soup);
  const KdTreeStats st = kd_tree_stats(tree);
  fmt::print("kd-tree           {} nodes, {} leaves, {} triangle references\n", st.nodes, st.leaves, st.references);
  try {
    validate_kd_coverage(tree, soup);
  } catch (const std::logic_error& e) {
    fmt::print("FAILED: {}\n", e.what());
    throw CompareFailed{};
  }
  fmt::print("seconds           {:.2f}\nCERTIFIED\n",
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

void run(const VerifyArgs& a) {
  const auto cap = limit_threads(a.threads);
  const TriangleSoup soup = load_scene(a.scene, a.allow_nonfinite, true);
  if (TreeFileReader(a.tree).kind() == TreeKind::Kd) return run_kd(a, soup);
  const auto file = std::make_shared<const TreeFileReader>(a.tree);
  const VerifyInput in = read_verify_input(*file, soup);
  std::uint64_t leaves = 0;
  for (const VerifyNode& n : in.nodes) leaves += n.plane == VerifyNode::kLeaf;
  ProgressBar bar("verify", leaves, "leaves", ProgressBar::stderr_is_terminal());
  VerifyConfig opt;
  opt.threads = a.threads;
  opt.strict_extras = a.strict;
  opt.progress = [&bar](std::uint64_t done, std::uint64_t) { bar.set(done); };
  const VerifyReport r = verify_bsp(soup, in, opt);
  bar.finish();
  print_report(r);
  if (!r.certified) {
    fmt::print("FAILED: {}\n", r.failure->describe());
    throw CompareFailed{};
  }
  if (const std::string problem = bsp_tree_load_problem(soup, file); !problem.empty()) {
    fmt::print("FAILED: the tree is exact, but bsprt's tracers refuse the file: {}\n", problem);
    throw CompareFailed{};
  }
  fmt::print("CERTIFIED\n");
}

}  // namespace

void register_verify(CLI::App& app) {
  auto args = std::make_shared<VerifyArgs>();
  CLI::App* cmd = app.add_subcommand("verify", "prove a BSP (or kd) tree file correct for a scene (exact, independent of the builder)");
  cmd->add_option("SCENE", args->scene, kSceneHelp)->required();
  cmd->add_option("TREE", args->tree, "tree file (bsprt build --accel bsp|kd -o TREE)")->required();
  cmd->add_option("--threads", args->threads, "worker threads (0 = all cores)")
      ->check(integer_in(0, kMaxThreads));
  cmd->add_flag("--strict", args->strict, "fail on listed triangles that do not touch the leaf's cell");
  cmd->add_flag("--allow-nonfinite", args->allow_nonfinite, "keep triangles with NaN/Inf corners (degenerate)");
  cmd->callback([args] { run(*args); });
}

}  // namespace bsprt::cli
