// `bsprt bench SCENE... [--rays ...] [--modes ...] [--count N] [--error-count M]
// [--threads T] [-o DIR]`: every mode on the same rays and threads in one
// process; speed, work, memory and error against the exact reference. Writes
// DIR/PREFIX.md, .csv and .json and prints a summary with ratios vs kd and
// vs Embree (robust). The work is in apps/bench_runner.h.
#include <fmt/core.h>

#include <filesystem>
#include <fstream>
#include <memory>

#include "apps/bench_report.h"
#include "apps/bench_runner.h"
#include "apps/cli_common.h"
#include "apps/progress.h"
#include "bsprt/error.h"

namespace bsprt::cli {
namespace {

struct BenchArgs {
  std::vector<std::string> scenes;
  std::vector<std::string> rays = {"primary", "random", "vertex", "edge"};
  std::vector<std::string> modes = {"kd", "kd-float", "bsp", "bsp-float", "bsp-zero-eps", "embree", "embree-fast"};
  std::size_t count = 262144;
  std::size_t error_count = 20000;
  int threads = 0;
  int runs = 2;
  std::uint64_t seed = 1;
  std::string output = "bench-out";
  std::string prefix = "bench";
  std::string cameras;  ///< camera file: primary rays of the scenes it names
};

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
  if (!f) throw InputError(path.string(), "cannot write");
}

/// The summary printed on stdout: one line per row with the ratios.
void print_summary(const BenchResult& r) {
  fmt::print("bench: {} threads, packets of {} ({})\n", r.threads, r.packet_width, r.isa);
  fmt::print("{:<16} {:<8} {:<14} {:>9} {:>10} {:>10} {:>7} {:>9} {:>8} {:>8} {:>8}\n", "scene", "rays", "mode",
             "build s", "Mrays/s", "packet", "vs kd", "vs embree", "lost", "farther", "extra");
  for (const BenchRow& row : r.rows) {
    const double vk = bench_speed_ratio(r, row, "kd"), ve = bench_speed_ratio(r, row, "embree");
    fmt::print("{:<16} {:<8} {:<14} {:>9.3f} {:>10.2f} {:>10} {:>7} {:>9} {:>8} {:>8} {:>8}\n", row.scene, row.ray_set,
               row.mode, row.build_seconds, row.mrays_single,
               row.packet_width > 1 ? fmt::format("{:.2f}", row.mrays_packet) : "-",
               vk > 0 ? fmt::format("{:.2f}", vk) : "-", ve > 0 ? fmt::format("{:.2f}", ve) : "-",
               row.error_rays ? fmt::format("{}", row.error.lost) : "-",
               row.error_rays ? fmt::format("{}", row.error.farther) : "-",
               row.error_rays ? fmt::format("{}", row.error.extra) : "-");
  }
  for (const std::string& n : r.notes) fmt::print("note: {}\n", n);
}

/// The output directory, made now (before any work), and the prefix a plain
/// file name, so that no run ends on an unwritable -o or writes outside it.
std::filesystem::path output_dir(const BenchArgs& a) {
  if (a.prefix.empty() || a.prefix.find('/') != std::string::npos || a.prefix == "." || a.prefix == "..")
    throw UsageError("--prefix must be a plain file name (no '/'), not '" + a.prefix + "'");
  const std::filesystem::path dir(a.output);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw InputError(a.output, "cannot make the output directory (-o): " +
                                   (ec ? ec.message() : std::string("a file of that name exists")));
  return dir;
}

void run(const BenchArgs& a) {
  BenchOptions o;
  o.ray_sets = a.rays, o.modes = a.modes, o.count = a.count, o.error_count = a.error_count;
  o.threads = a.threads, o.runs = a.runs, o.seed = a.seed;
  check_bench_options(o);  // before any scene is loaded or -o is made
  const std::filesystem::path dir = output_dir(a);
  const auto cap = limit_threads(a.threads);
  std::vector<BenchScene> scenes;
  for (const std::string& s : a.scenes) {
    scenes.push_back(load_bench_scene(s));
    fmt::print(stderr, "bench: scene {} ({} triangles)\n", scenes.back().name, scenes.back().soup.size());
  }
  if (!a.cameras.empty()) o.cameras = read_camera_file(a.cameras);
  std::unique_ptr<ProgressBar> bar;
  o.progress = [&](const std::string&, std::size_t done, std::size_t total) {
    if (!bar) bar = std::make_unique<ProgressBar>("bench", total, "steps", ProgressBar::stderr_is_terminal());
    bar->set(done);
  };
  const BenchResult result = run_bench(scenes, o);
  if (bar) bar->finish();
  write_file(dir / (a.prefix + ".md"), bench_markdown(result));
  write_file(dir / (a.prefix + ".csv"), bench_csv(result));
  write_file(dir / (a.prefix + ".json"), bench_json(result));
  // The per-ray-set summaries docs/performance.md pastes in (scripts/docs.sh).
  std::string summaries;
  for (const std::string& set : o.ray_sets) {
    const std::string speed = bench_speed_summary(result, set), error = bench_error_summary(result, set);
    for (const auto& [kind, text] : {std::pair{"-speed-", speed}, std::pair{"-error-", error}}) {
      if (text.empty()) continue;
      write_file(dir / (a.prefix + kind + set + ".md"), text);
      summaries += std::string(" ") + kind + set;
    }
  }
  print_summary(result);
  fmt::print("wrote {0}.md, {0}.csv, {0}.json{1}\n", (dir / a.prefix).string(),
             summaries.empty() ? "" : " and summaries" + summaries + " (.md)");
}

}  // namespace

void register_bench(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "benchmark modes on the same rays: speed, work, memory and error against the exact reference");
  cmd->add_option("SCENE", args->scenes,
                  "mesh files, 'default', icosphere:L (generated, 20*4^L triangles), or twin:SCENE (every "
                  "triangle listed twice, the copy reversed)")
      ->required();
  cmd->add_option("--rays", args->rays, "ray sets: primary, random, vertex, edge, inside (icospheres only)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--modes", args->modes, "accelerators (see --accel of trace)")->delimiter(',')->capture_default_str();
  cmd->add_option("--count", args->count, "rays per set for speed")
      ->capture_default_str()->check(integer_in(1, kMaxRays));
  cmd->add_option("--error-count", args->error_count,
                  "rays per set (every k-th of the --count rays) checked against the exact reference and counted for "
                  "node visits and triangle tests (0 = no check, counters on all --count rays)")
      ->capture_default_str()->check(integer_in(0, kMaxRays));
  cmd->add_option("--threads", args->threads, "worker threads for every mode (0 = all cores)")
      ->check(integer_in(0, kMaxThreads))->capture_default_str();
  cmd->add_option("--runs", args->runs,
                  "timing rounds: each round times every mode once (single rays, then packets), and a mode's fastest "
                  "round counts")
      ->capture_default_str()->check(integer_in(1, 1000));
  cmd->add_option("--seed", args->seed, "ray-set seed")->capture_default_str();
  cmd->add_option("--cameras", args->cameras,
                  "camera file (e.g. bench/cameras.json): a scene it names traces its primary rays from that camera")
      ->check(non_empty_path());
  cmd->add_option("-o,--output", args->output, "directory for PREFIX.md, .csv, .json")->capture_default_str();
  cmd->add_option("--prefix", args->prefix, "base name of the output files")->capture_default_str();
  cmd->callback([args] { run(*args); });
}

}  // namespace bsprt::cli
