/// \file tree.cpp
/// bsprt::Tree, build and verify (include/bsprt/tree.h): the builders and the
/// independent verifier behind the public API, trees held as tree-file images.
#include "bsprt/tree.h"

#include <oneapi/tbb/task_arena.h>

#include <chrono>

#include "builder/accel_factory.h"
#include "builder/bsp/bsp_build.h"
#include "builder/bsp/bsp_flat_io.h"
#include "builder/bsp/bsp_flatten.h"
#include "builder/kd/kd_build.h"
#include "builder/kd/kd_file.h"
#include "builder/tree_file.h"
#include "bsprt/error.h"
#include "geometry/core/fp_env.h"
#include "verify/verify_file.h"
#include "verify/verify.h"

namespace bsprt {

struct Tree::Impl {
  Scene scene;
  std::shared_ptr<const TreeFileReader> reader;  ///< holds the file image, once; its sections are views
  double build_seconds = 0.0;
};

Tree::Tree(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

const Tree::Impl& Tree::impl() const {
  if (!impl_)
    throw UsageError("bsprt::Tree used after it was moved from (only assigning to it or destroying it is "
                     "allowed)");
  return *impl_;
}

namespace {

using Clock = std::chrono::steady_clock;


/// Progress and cancellation of one build: reports pass through `progress`,
/// `cancel` is polled at each, and the last report is (total, total).
struct BuildMonitor {
  const BuildOptions& o;
  void report(double done, double total) const {
    if (o.cancel && o.cancel()) throw Cancelled();
    if (o.progress) o.progress(done, total);
  }
};

std::vector<std::byte> build_kd_bytes(const TriangleSoup& soup, const BuildOptions& o, const BuildMonitor& m) {
  m.report(0, 1);
  const KdConfig config;
  auto run = [&] { return build_kd(soup, config); };
  KdTree tree = run_ieee(o.threads, run);
  m.report(1, 1);
  return kd_tree_file(tree, soup, config).bytes();
}

std::vector<std::byte> build_bsp_bytes(const TriangleSoup& soup, const BuildOptions& o, const BuildMonitor& m) {
  BspConfig config;
  config.threads = o.threads;
  config.membership = o.membership == Membership::Closed ? BspMembership::Closed : BspMembership::Area;
  BspBuildReport report;
  const BspTree tree = build_bsp(soup, config, &report, [&m](double done, double total) { m.report(done, total); });
  const FlatBspTree flat = flatten_bsp(soup, tree);
  const BspReportRecord record{report.seconds, report.exact.filter_calls, report.exact.symbolic,
                               report.exact.exact_fallbacks, report.exact.exact_points};
  return bsp_tree_file(soup, tree, flat, &record).bytes();
}

}  // namespace

Tree build(const Scene& scene, const BuildOptions& options) {
  check_threads(options.threads, "BuildOptions::threads");
  if (options.kind != TreeKind::Kd && options.kind != TreeKind::Bsp)
    throw UsageError("BuildOptions::kind must be TreeKind::Kd or TreeKind::Bsp, not " +
                     std::to_string(std::uint32_t(options.kind)));
  if (options.membership != Membership::Area && options.membership != Membership::Closed)
    throw UsageError("BuildOptions::membership must be Membership::Area or Membership::Closed, not " +
                     std::to_string(int(options.membership)));
  const IeeeScope ieee;  // flatten_bsp and the file writer on this thread (fp_env.h)
  const auto t0 = Clock::now();
  const BuildMonitor monitor{options};
  auto impl = std::make_shared<Tree::Impl>(Tree::Impl{scene, nullptr, 0.0});
  auto bytes = std::make_shared<const std::vector<std::byte>>(
      options.kind == TreeKind::Kd ? build_kd_bytes(scene.soup(), options, monitor)
                                   : build_bsp_bytes(scene.soup(), options, monitor));
  impl->reader = std::make_shared<const TreeFileReader>("(built in memory)", std::move(bytes));
  impl->build_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return Tree(std::move(impl));
}

Tree Tree::load(const std::string& path, const Scene& scene) {
  const IeeeScope ieee;
  auto impl = std::make_shared<Impl>(Impl{scene, std::make_shared<const TreeFileReader>(path), 0.0});
  impl->reader->check_scene(scene.soup());
  return Tree(std::move(impl));
}

void Tree::save(const std::string& path) const { write_tree_file_image(path, impl().reader->image()); }

TreeKind Tree::kind() const { return impl().reader->kind(); }
std::span<const std::byte> Tree::bytes() const { return impl().reader->image(); }
double Tree::build_seconds() const { return impl().build_seconds; }
const Scene& Tree::scene() const { return impl().scene; }
std::shared_ptr<const TreeFileReader> Tree::file() const { return impl().reader; }

namespace {

Certificate verify_kd(const TriangleSoup& soup, const TreeFileReader& file) {
  Certificate c;
  const KdTree tree = read_kd_tree(file, soup);
  const KdTreeStats st = kd_tree_stats(tree);
  c.nodes = st.nodes;
  c.leaves = st.leaves;
  try {
    validate_kd_coverage(tree, soup);
    c.certified = true;
  } catch (const std::logic_error& e) {
    c.failure = e.what();
  }
  return c;
}

Certificate verify_bsp_tree(const TriangleSoup& soup, const std::shared_ptr<const TreeFileReader>& file,
                            const VerifyOptions& options) {
  const VerifyInput in = read_verify_input(*file, soup);
  VerifyConfig internal;
  internal.threads = options.threads;
  internal.strict_extras = options.strict;
  const VerifyReport r = verify_bsp(soup, in, internal);
  Certificate c;
  c.certified = r.certified;
  c.nodes = r.nodes;
  c.leaves = r.leaves;
  c.pairs = r.pairs;
  c.exact_fallbacks = r.exact_fallbacks;
  if (r.failure) {
    c.failure = r.failure->describe();
    c.node = r.failure->node;
    c.triangle = r.failure->triangle;
    c.witness = r.failure->witness;
  }
  if (c.certified)
    if (const std::string problem = bsp_tree_load_problem(soup, file); !problem.empty()) {
      c.certified = false;
      c.failure = "the tree is exact, but bsprt's tracers refuse the file: " + problem;
    }
  return c;
}

}  // namespace

Certificate verify(const Scene& scene, const Tree& tree, const VerifyOptions& options) {
  if (tree.scene().fingerprint() != scene.fingerprint() || tree.scene().triangle_count() != scene.triangle_count())
    throw UsageError("verify: the tree was built for another scene (fingerprint mismatch)");
  check_threads(options.threads, "VerifyOptions::threads");
  const auto t0 = Clock::now();
  const std::shared_ptr<const TreeFileReader> file = tree.file();
  auto run = [&] {
    return file->kind() == TreeKind::Kd ? verify_kd(scene.soup(), *file) : verify_bsp_tree(scene.soup(), file, options);
  };
  Certificate c = run_ieee(options.threads, run);  // IEEE arithmetic in every task (fp_env.h)
  c.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return c;
}

}  // namespace bsprt
