#include "apps/cli_common.h"

#include <filesystem>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <vector>

#include <fmt/core.h>

#include "apps/progress.h"
#include "geometry/scenes/default_scene.h"
#include "bsprt/error.h"

namespace bsprt::cli {

namespace {
/// The text of an option value as a double, or nullopt when it is not a whole number literal.
std::optional<double> as_number(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return std::nullopt;
  return v;
}
}  // namespace

CLI::Validator number_above(double lo) {
  return CLI::Validator(
      [lo](std::string& s) -> std::string {
        const std::optional<double> v = as_number(s);
        return v && *v > lo ? "" : fmt::format("must be a number > {}, not '{}'", lo, s);
      },
      fmt::format("NUMBER > {}", lo));
}

CLI::Validator number_at_least(double lo) {
  return CLI::Validator(
      [lo](std::string& s) -> std::string {
        const std::optional<double> v = as_number(s);
        return v && *v >= lo && std::isfinite(*v) ? "" : fmt::format("must be a finite number >= {}, not '{}'", lo, s);
      },
      fmt::format("NUMBER >= {}", lo));
}

CLI::Validator number_in_open(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        const std::optional<double> v = as_number(s);
        return v && *v > lo && *v < hi ? "" : fmt::format("must be a number in ({}, {}), not '{}'", lo, hi, s);
      },
      fmt::format("NUMBER in ({}, {})", lo, hi));
}

CLI::Validator integer_in(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        const std::optional<double> v = as_number(s);
        const bool ok = v && *v >= double(lo) && *v <= double(hi) && *v == std::floor(*v) &&
                        s.find_first_of(".eE") == std::string::npos;
        return ok ? "" : fmt::format("must be a whole number from {} to {}, not '{}'", lo, hi, s);
      },
      fmt::format("INT in [{}, {}]", lo, hi));
}

CLI::Validator non_empty_path() {
  return CLI::Validator([](std::string& s) -> std::string { return s.empty() ? "must not be an empty path" : ""; },
                        "PATH");
}

CLI::Validator output_file() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        if (s.empty()) return "must not be an empty path";
        std::error_code ec;
        const std::filesystem::path p(s);
        if (std::filesystem::is_directory(p, ec) || s.back() == '/')
          return "'" + s + "' is a directory; give a file to write";
        const std::filesystem::path parent = p.parent_path();
        if (!parent.empty() && !std::filesystem::is_directory(parent, ec))
          return "the folder '" + parent.string() + "' of '" + s + "' does not exist";
        return "";
      },
      "FILE");
}

void reject_given(const CLI::App& cmd, const std::vector<std::string>& names, const std::string& why) {
  std::string given;
  for (const std::string& n : names)
    if (cmd.get_option(n)->count() > 0) given += (given.empty() ? "" : ", ") + n;
  if (!given.empty()) throw UsageError(given + ": " + why);
}

void add_trace_options(CLI::App& cmd, TraceOptions& o, const std::string& default_accel) {
  o.accel = default_accel;
  std::string names;
  for (const std::string& n : accel_names()) names += (names.empty() ? "" : "|") + n;
  cmd.add_option("--accel", o.accel, "accelerator: " + names)->capture_default_str();
  cmd.add_option("--tree", o.tree, "tree file written by `bsprt build` (kd, bsp); built in memory if absent")
      ->check(non_empty_path());
  cmd.add_option("--threads", o.threads, "worker threads (0 = all cores)")
      ->check(integer_in(0, kMaxThreads))->capture_default_str();
  cmd.add_option("--packets", o.packets, "rays per packet: 1 (single rays), 4, 8 or 16")
      ->check(CLI::IsMember({1, 4, 8, 16}))
      ->capture_default_str();
  cmd.add_option("--membership", o.membership,
                 "BSP builds: which triangles a leaf lists: area (positive-area overlap, the default) or closed "
                 "(every triangle touching the closed cell)")
      ->capture_default_str();
  cmd.add_option("--top-slots", o.top_slots,
                 "bsp-top, bsp-bvh8 (and -float): largest BSP subtree (8-byte slots) under one box of the top "
                 "(default: 1024 for bsp-top, 1 for bsp-bvh8)")
      ->check(integer_in(1, 1 << 27));
  cmd.add_option("--single-rays", o.single_rays,
                 "bsp, bsp-float, bsp-zero-eps: how single rays run: auto (interleaved for incoherent rays with "
                 "tfar = inf on trees of 32 KiB or more), sequential or interleaved; the hits are the same")
      ->check(CLI::IsMember({"auto", "sequential", "interleaved"}))
      ->capture_default_str();
  cmd.add_flag("--allow-nonfinite", o.allow_nonfinite,
               "keep triangles with NaN/Inf corners (flagged degenerate, never hit) instead of failing");
}

TriangleSoup load_scene(const std::string& path, bool allow_nonfinite, bool verbose) {
  if (path.rfind(kTwinPrefix, 0) == 0) {
    const std::string file = path.substr(kTwinPrefix.size());
    if (file.empty()) throw UsageError("expected twin:FILE (a mesh whose triangles are listed twice), not 'twin:'");
    TriangleSoup soup = with_reversed_copies(load_scene(file, allow_nonfinite, verbose));
    if (verbose)
      fmt::print(stderr, "scene: every triangle listed twice (copy n + i = triangle i reversed): {} triangles\n",
                 soup.size());
    return soup;
  }
  if (path.empty()) throw UsageError("SCENE is an empty string: give a mesh file, or 'default' for the embedded scene");
  if (path == "default") {
    TriangleSoup soup = make_default_scene();
    if (verbose)
      fmt::print(stderr, "scene: embedded default scene, {} triangles, {} vertices\n", soup.size(),
                 soup.vertices.size());
    return soup;
  }
  LoadOptions options;
  options.allow_nonfinite = allow_nonfinite;
  LoadReport report;
  TriangleSoup soup = load_mesh(path, options, &report);
  if (verbose)
    fmt::print(stderr, "scene: {} ({}): {} triangles from {} faces, {} vertices ({} unreferenced), {} degenerate{}, loaded in {:.3f} s\n",
               path, report.format, report.triangles, report.faces, report.vertices,
               report.unreferenced_vertices, report.degenerate,
               report.nonfinite_triangles ? fmt::format(" ({} with non-finite corners)", report.nonfinite_triangles)
                                          : std::string(),
               report.seconds);
  return soup;
}

BspMembership parse_membership(const std::string& name) {
  if (name == "area") return BspMembership::Area;
  if (name == "closed") return BspMembership::Closed;
  throw UsageError("--membership must be area or closed, not '" + name + "'");
}

std::unique_ptr<tbb::global_control> limit_threads(int threads) {
  if (threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               std::size_t(threads));
}

namespace {
/// Which of the accelerator-specific options `o.accel` uses.
struct UsedOptions {
  bool single_rays, top_slots, membership, packets;
};
UsedOptions used_options(const TraceOptions& o) {
  const AccelInfo& a = accel_info(o.accel);
  return {a.uses_single_rays, a.uses_top_slots, a.tree == AccelTree::Bsp && o.tree.empty(), a.packets};
}
}  // namespace

std::vector<std::string> ignored_options(const TraceOptions& o) {
  const TraceOptions defaults;
  const UsedOptions used = used_options(o);
  std::vector<std::string> ignored;
  if (o.single_rays != defaults.single_rays && !used.single_rays)
    ignored.push_back("--single-rays (bsp, bsp-float, bsp-zero-eps only)");
  if (o.top_slots != defaults.top_slots && !used.top_slots)
    ignored.push_back("--top-slots (bsp-top, bsp-top-float, bsp-bvh8, bsp-bvh8-float only)");
  // An accelerator without packets traces a batch ray by ray: --packets 16
  // was accepted and reported in --json as if packets had run (review of 2026-12-07).
  if (o.packets != defaults.packets && o.packets > 1 && !used.packets)
    ignored.push_back("--packets (" + o.accel + " traces single rays only)");
  if (o.membership != defaults.membership && !used.membership)
    ignored.push_back(o.tree.empty() ? "--membership (BSP accelerators only)"
                                     : "--membership (a BSP built in memory only; the tree file fixed it when it was "
                                       "built: bsprt build --membership)");
  return ignored;
}

TraceOptions without_ignored_options(TraceOptions o) {
  const TraceOptions defaults;
  const UsedOptions used = used_options(o);
  if (!used.single_rays) o.single_rays = defaults.single_rays;
  if (!used.top_slots) o.top_slots = defaults.top_slots;
  if (!used.membership) o.membership = defaults.membership;
  if (!used.packets) o.packets = 1;
  return o;
}

std::unique_ptr<Accelerator> make_accel(const TraceOptions& o, const TriangleSoup& soup) {
  const std::vector<std::string> ignored = ignored_options(o);
  if (!ignored.empty()) {
    std::string list;
    for (const std::string& name : ignored) list += (list.empty() ? "" : ", ") + name;
    throw UsageError("--accel " + o.accel + " does not use " + list);
  }
  AccelOptions options;
  options.tree_path = o.tree;
  options.threads = o.threads;
  options.bsp.membership = parse_membership(o.membership);
  options.top_slots = o.top_slots;
  options.single_rays = o.single_rays == "sequential"    ? BspSingleRays::Sequential
                        : o.single_rays == "interleaved" ? BspSingleRays::Interleaved
                                                         : BspSingleRays::Auto;
  const bool building = o.tree.empty() && accel_info(o.accel).tree != AccelTree::None;
  std::unique_ptr<ProgressBar> bar;
  if (building && ProgressBar::stderr_is_terminal()) {
    bar = std::make_unique<ProgressBar>("building " + o.accel, 1000, "permille", true);
    options.progress = [&bar](double done, double total) {
      bar->set(total > 0 ? std::uint64_t(1000.0 * done / total) : 0);
    };
  }
  return make_tracer(o.accel, soup, options);
}

}  // namespace bsprt::cli
