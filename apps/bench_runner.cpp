/// \file bench_runner.cpp
/// run_bench: one process, the same rays and threads for every mode; errors
/// against ExactTracer on a strided subset of each ray set.
#include "apps/bench_runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <random>

#include <fmt/core.h>
#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/combinable.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include "builder/accel_factory.h"
#include "builder/bsp/bsp_build.h"
#include "builder/bsp/bsp_flat_io.h"
#include "builder/bsp/bsp_flatten.h"
#include "geometry/scenes/camera.h"
#include "geometry/scenes/default_scene.h"
#include "bsprt/error.h"
#include "apps/cli_common.h"
#include "geometry/io/load_mesh.h"
#include "geometry/scenes/ray_gen.h"
#include "robust/exact_tracer.h"
#include "traverse/simd/cpu_features.h"
#include "traverse/trace_parallel.h"
#include "geometry/core/fp_env.h"

namespace bsprt {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// Modes whose speed is measured on the error subset only (too slow for more).
bool is_slow_mode(const std::string& mode) { return accel_info(mode).slow; }

bool is_bsp_mode(const std::string& mode) { return accel_info(mode).tree == AccelTree::Bsp; }

/// About n primary rays from `cam`, 4:3, in 8x8 tiles (ray_gen.h).
std::vector<Ray> tiled_primary_rays(const Camera& cam, std::size_t n) {
  const int width = std::max(8, int(std::lround(std::sqrt(double(n) * 4.0 / 3.0))));
  const int height = std::max(8, int(std::lround(double(n) / width)));
  return bsprt::tiled_primary_rays(cam, width, height);
}

/// The scene's camera from BenchOptions::cameras (matched by file stem), or one framing it.
Camera bench_camera(const BenchScene& scene, const std::vector<NamedCamera>& cameras) {
  for (const NamedCamera& c : cameras)
    if (!c.scene.empty() && std::filesystem::path(c.scene).stem().string() == scene.name) return c.camera;
  return frame_bounds(scene.soup.bounds());
}

/// Rays from origins uniform in `ball` shrunk to half its radius, directions
/// uniform on the sphere: on a closed surface around the ball, every ray hits.
std::vector<Ray> inside_rays(Vec3f center, float radius, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Ray> rays(n);
  for (Ray& r : rays) {
    Vec3f p;
    do p = {u(rng), u(rng), u(rng)};
    while (dot(p, p) > 1.0f);
    r.org = center + p * (0.5f * radius);
    const float z = u(rng), phi = std::numbers::pi_v<float> * u(rng);
    const float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
    r.dir = {s * std::cos(phi), s * std::sin(phi), z};
  }
  return rays;
}

/// The ray set named `name` for `scene`, or nothing when it does not apply.
std::optional<std::vector<Ray>> make_ray_set(const std::string& name, const BenchScene& scene, std::size_t n,
                                             std::uint64_t seed, const std::vector<NamedCamera>& cameras) {
  if (name == "primary") return tiled_primary_rays(bench_camera(scene, cameras), n);
  if (name == "inside") {
    if (!scene.inside_ball) return std::nullopt;
    return inside_rays(scene.inside_ball->first, scene.inside_ball->second, n, seed);
  }
  return make_rays(parse_ray_set(name), scene.soup, n, seed);
}

/// Every `stride`-th ray, so the subset spans the whole set (the whole image).
std::vector<Ray> strided_subset(const std::vector<Ray>& rays, std::size_t n) {
  if (n >= rays.size()) return rays;
  std::vector<Ray> out;
  out.reserve(n);
  const double stride = double(rays.size()) / double(n);
  for (std::size_t i = 0; i < n; ++i) out.push_back(rays[std::size_t(double(i) * stride)]);
  return out;
}

/// A built accelerator with its build time.
struct BuiltMode {
  std::string mode;
  std::unique_ptr<Accelerator> tracer;
  double build_seconds = 0.0;
};

/// Builds the exact BSP tree once, flattens it and writes it to a temporary
/// tree file, so every BSP mode loads the same tree. Returns build seconds.
/// Builds the exact BSP and its flattening once (every BSP mode traces it), kept
/// as an in-memory tree file; `seconds` receives the build time (without the file).
std::shared_ptr<const TreeFileReader> build_bsp_once(const TriangleSoup& soup, int threads, double& seconds) {
  const auto t0 = Clock::now();
  BspConfig config;
  config.threads = threads;
  const BspTree exact = build_bsp(soup, config);
  const FlatBspTree flat = flatten_bsp(soup, exact);
  seconds = seconds_since(t0);
  return std::make_shared<const TreeFileReader>("(bench: in-memory tree)", bsp_tree_file(soup, exact, flat).bytes());
}

/// Builds every mode for one scene (BSP modes share one build).
std::vector<BuiltMode> build_modes(const BenchScene& scene, const BenchOptions& o, int threads,
                                   const std::function<void(const std::string&)>& step) {
  std::vector<BuiltMode> built;
  std::shared_ptr<const TreeFileReader> bsp_tree;
  double bsp_seconds = 0.0;
  for (const std::string& mode : o.modes) {
    step(fmt::format("{}: building {}", scene.name, mode));
    AccelOptions options;
    options.threads = threads;
    double seconds = 0.0;
    if (is_bsp_mode(mode)) {
      if (!bsp_tree) bsp_tree = build_bsp_once(scene.soup, threads, bsp_seconds);
      options.tree_file = bsp_tree;
      seconds = bsp_seconds;
    }
    const auto t0 = Clock::now();
    std::unique_ptr<Accelerator> tracer = make_tracer(mode, scene.soup, options);
    if (!is_bsp_mode(mode)) seconds = seconds_since(t0);
    built.push_back({mode, std::move(tracer), seconds});
  }
  return built;
}

/// Exact reference hits of `rays` (parallel; the slow part of the run).
std::vector<Hit> exact_hits(const TriangleSoup& soup, const std::vector<Ray>& rays) {
  const ExactTracer exact(soup);
  std::vector<Hit> hits(rays.size());
  ParallelTrace o;
  o.block = 64;
  trace_parallel(exact, rays, hits, o);
  return hits;
}

/// A mode's timing on one ray set: its fastest pass, single rays and packets.
struct ModeTiming {
  double single = 1e30;
  double packet = 1e30;
  std::size_t hits = 0;  ///< rays of the timed set that hit (single rays, first round)
};

/// The rays a mode is timed on: slow modes (brute force, the exact
/// reference) take the error subset, when there is one.
const std::vector<Ray>& timed_rays(const BuiltMode& m, const std::vector<Ray>& rays,
                                   const std::vector<Ray>& subset) {
  return is_slow_mode(m.mode) && !subset.empty() ? subset : rays;
}

/// Packet width a mode is timed with: certified modes and box tops trace
/// packets as single rays, so they get no packet row (width 1).
int packet_width_of(const BuiltMode& m, int isa_width) { return accel_info(m.mode).packets ? isa_width : 1; }

/// Times every mode on one ray set in rounds: each round traces the set once
/// with every mode (single rays, then packets), so that the slow and fast
/// phases of a shared machine fall on all modes alike, and a mode's time is
/// its fastest round. Timing the runs of one mode back to back put whole
/// phases on one mode: ratios of the same two modes moved by up to 0.28
/// between runs of the same build, 0.12 in rounds (docs/notes/2026-12-07-bench-rounds.md).
/// Slow modes take one pass. `step` is called once per mode and round.
std::vector<ModeTiming> time_modes(const std::vector<BuiltMode>& built, const std::vector<Ray>& rays,
                                   const std::vector<Ray>& subset, const BenchOptions& o, int isa_width,
                                   const std::function<void(const std::string&)>& step, const std::string& label) {
  std::vector<ModeTiming> t(built.size());
  const int rounds = o.runs;  // at least 1 (check_bench_options)
  std::vector<Hit> hits;
  for (int r = 0; r < rounds; ++r) {
    for (std::size_t i = 0; i < built.size(); ++i) {
      const BuiltMode& m = built[i];
      step(fmt::format("{}, {}: timing round {} of {}", label, m.mode, r + 1, rounds));
      if (r > 0 && is_slow_mode(m.mode)) continue;
      const std::vector<Ray>& timed = timed_rays(m, rays, subset);
      t[i].single = std::min(t[i].single, time_trace(*m.tracer, timed, hits, 1, 1));
      if (r == 0)
        t[i].hits = std::size_t(std::count_if(hits.begin(), hits.end(), [](const Hit& h) { return h.hit(); }));
      const int width = packet_width_of(m, isa_width);
      if (width > 1) t[i].packet = std::min(t[i].packet, time_trace(*m.tracer, timed, hits, width, 1));
    }
  }
  return t;
}

/// One built mode's row on one ray set: its timing (time_modes), work per
/// ray counted in a separate pass, and its error against the reference.
BenchRow measure_mode(const BuiltMode& m, const ModeTiming& timing, const std::vector<Ray>& rays,
                      const std::vector<Ray>& subset, const std::vector<Hit>& reference, int isa_width) {
  BenchRow row;
  row.mode = m.mode;
  row.build_seconds = m.build_seconds;
  row.memory_bytes = m.tracer->memory_bytes();
  const std::vector<Ray>& timed = timed_rays(m, rays, subset);
  row.rays = timed.size();
  row.mrays_single = double(timed.size()) / timing.single * 1e-6;
  row.hits = timing.hits;
  row.packet_width = packet_width_of(m, isa_width);
  if (row.packet_width > 1) row.mrays_packet = double(timed.size()) / timing.packet * 1e-6;
  const RayCounters c = count_work(*m.tracer, subset.empty() ? timed : subset);
  const double n = double(std::max<std::uint64_t>(1, c.rays ? c.rays : (subset.empty() ? timed : subset).size()));
  row.kd_visits = double(c.kd_node_visits) / n;
  row.bsp_visits = double(c.bsp_node_visits) / n;
  row.leaf_visits = double(c.leaf_visits) / n;
  row.triangle_tests = double(c.triangle_tests) / n;
  row.box_visits = double(c.box_node_visits) / n;
  row.rule_decisions = double(c.rule_decisions) / n;
  row.exact_decisions = double(c.exact_decisions) / n;
  row.exact_rays = double(c.exact_rays) / n;
  if (!subset.empty()) {
    std::vector<Hit> tested;
    time_trace(*m.tracer, subset, tested, 1, 1);
    row.error_rays = subset.size();
    row.error = compare_hits(reference, tested);
    row.median_t_ulps = median_t_ulps(reference, tested);
  }
  return row;
}

/// Progress steps of one ray set: the reference, each mode in each timing
/// round, and each mode's work and error.
std::size_t steps_per_set(std::size_t modes, const BenchOptions& o) {
  return 1 + modes * (std::size_t(o.runs) + 1);
}

/// All ray sets of one scene.
void bench_scene(const BenchScene& scene, const BenchOptions& o, int threads, int isa_width, BenchResult& result,
                 const std::function<void(const std::string&)>& step) {
  const std::vector<BuiltMode> built = build_modes(scene, o, threads, step);
  for (const std::string& set : o.ray_sets) {
    const auto rays = make_ray_set(set, scene, o.count, o.seed, o.cameras);
    if (!rays) {
      result.notes.push_back(fmt::format("{}: ray set '{}' skipped (no known inside region)", scene.name, set));
      for (std::size_t i = 0; i < steps_per_set(built.size(), o); ++i) step(fmt::format("{}: {} skipped", scene.name, set));
      continue;
    }
    const std::vector<Ray> subset = o.error_count ? strided_subset(*rays, o.error_count) : std::vector<Ray>{};
    step(fmt::format("{}: exact reference on {} {} rays", scene.name, subset.size(), set));
    const std::vector<Hit> reference = subset.empty() ? std::vector<Hit>{} : exact_hits(scene.soup, subset);
    const std::vector<ModeTiming> timing =
        time_modes(built, *rays, subset, o, isa_width, step, fmt::format("{}: {} rays", scene.name, set));
    for (std::size_t i = 0; i < built.size(); ++i) {
      const BuiltMode& m = built[i];
      step(fmt::format("{}: {} rays, {}: work and error", scene.name, set, m.mode));
      BenchRow row = measure_mode(m, timing[i], *rays, subset, reference, isa_width);
      row.scene = scene.name;
      row.triangles = scene.soup.size();
      row.ray_set = set;
      result.rows.push_back(std::move(row));
    }
  }
}

}  // namespace

void check_bench_options(const BenchOptions& o) {
  // accel_info names the accepted modes, and an old name's replacement, as
  // trace and render do (bench said only "unknown mode"; review of 2026-12-07).
  for (std::size_t i = 0; i < o.modes.size(); ++i) {
    try {
      (void)accel_info(o.modes[i]);
    } catch (const UsageError& e) {
      throw UsageError(std::string("bench --modes: ") + e.what());
    }
    for (std::size_t j = 0; j < i; ++j)
      if (o.modes[i] == o.modes[j]) throw UsageError("--modes lists " + o.modes[i] + " twice");
  }
  for (std::size_t i = 0; i < o.ray_sets.size(); ++i) {
    const std::string& s = o.ray_sets[i];
    if (s != "inside" && s != "primary" && s != "random" && s != "vertex" && s != "edge")
      throw UsageError("bench --rays: unknown ray set '" + s + "' (expected primary, random, vertex, edge or inside)");
    // A set given twice made two tables under one heading and wrote its summary twice.
    for (std::size_t j = 0; j < i; ++j)
      if (s == o.ray_sets[j]) throw UsageError("--rays lists " + s + " twice");
  }
  if (o.count == 0) throw UsageError("bench: --count must be positive");
  if (o.runs < 1) throw UsageError("bench: --runs must be at least 1, not " + std::to_string(o.runs));
}

/// Traces all rays with `width`-wide packets over blocks of 1024 on all
/// threads of the current arena; returns seconds of the fastest of `runs`.
double time_trace(const Accelerator& tracer, const std::vector<Ray>& rays, std::vector<Hit>& hits, int width,
                  int runs) {
  hits.assign(rays.size(), Hit{});
  double best = 1e30;
  for (int r = 0; r < std::max(1, runs); ++r) {
    ParallelTrace o;
    o.packet_width = width;
    o.block = 1024;
    const auto t0 = Clock::now();
    trace_parallel(tracer, rays, hits, o);
    best = std::min(best, seconds_since(t0));
  }
  return best;
}

/// Work per ray, counted in a separate single-ray pass (counters cost time).
RayCounters count_work(const Accelerator& tracer, const std::vector<Ray>& rays) {
  tbb::combinable<RayCounters> local;
  // One trace() per ray, not trace_batch: the per-ray counters of the single-ray kernel.
  for_each_block(rays.size(), 256, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) tracer.trace(rays[i], &local.local());
  });
  RayCounters sum;
  local.combine_each([&](const RayCounters& c) { sum += c; });
  return sum;
}

bool bench_mode_is_certified(const std::string& mode) { return accel_info(mode).certified; }

double median_t_ulps(const std::vector<Hit>& reference, const std::vector<Hit>& tested) {
  std::vector<double> d;
  for (std::size_t i = 0; i < std::min(reference.size(), tested.size()); ++i)
    if (reference[i].hit() && tested[i].hit()) d.push_back(ulp_distance(reference[i].t, tested[i].t));
  if (d.empty()) return 0.0;
  std::nth_element(d.begin(), d.begin() + std::ptrdiff_t(d.size() / 2), d.end());
  return d[d.size() / 2];
}

BenchScene load_bench_scene(const std::string& spec) {
  BenchScene scene;
  if (spec.rfind(cli::kTwinPrefix, 0) == 0) {
    const std::string inner = spec.substr(cli::kTwinPrefix.size());
    if (inner.empty()) throw UsageError("bench: expected twin:SCENE, not '" + spec + "'");
    scene = load_bench_scene(inner);
    scene.name += "-twins";
    scene.soup = with_reversed_copies(scene.soup);
  } else if (spec.empty() || spec == "default") {
    scene.name = "default";
    scene.soup = make_default_scene();
  } else if (spec.rfind("icosphere:", 0) == 0) {
    const std::string levels = spec.substr(10);
    if (levels.empty() || levels.size() > 1 || levels[0] < '0' || levels[0] > '9')
      throw UsageError("bench: expected icosphere:L with L in 0..9, not '" + spec + "'");
    const int level = levels[0] - '0';
    scene.name = "icosphere-" + levels;
    scene.soup = make_icosphere({0.0f, 0.0f, 0.0f}, 1.0f, level);
    // The icosahedron's inradius is 0.79 of its circumradius; subdividing only grows it.
    scene.inside_ball = std::make_pair(Vec3f{0.0f, 0.0f, 0.0f}, 0.75f);
  } else {
    scene.name = std::filesystem::path(spec).stem().string();
    scene.soup = load_mesh(spec);
  }
  return scene;
}

BenchResult run_bench(const std::vector<BenchScene>& scenes, const BenchOptions& o) {
  check_bench_options(o);
  BenchResult result;
  const Isa isa = detected_isa();
  result.isa = isa_name(isa);
  result.packet_width = isa_width(isa);
  const IeeeScope ieee;  // this thread and, through the arena made under it, every task (fp_env.h)
  tbb::task_arena arena(o.threads > 0 ? o.threads : tbb::task_arena::automatic);
  result.threads = arena.max_concurrency();
  const std::size_t total = scenes.size() * (o.modes.size() + o.ray_sets.size() * steps_per_set(o.modes.size(), o));
  std::size_t done = 0;
  const auto step = [&](const std::string& what) {
    if (o.progress) o.progress(what, done, total);
    ++done;
  };
  arena.execute([&] {
    for (const BenchScene& scene : scenes) bench_scene(scene, o, result.threads, result.packet_width, result, step);
  });
  if (o.progress) o.progress("done", total, total);
  return result;
}

}  // namespace bsprt
