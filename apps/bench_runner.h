#pragma once
/// \file bench_runner.h
/// The library part of `bsprt bench`: for each scene and ray set, builds every
/// requested accelerator and traces the SAME rays on the SAME threads in ONE
/// process, measuring build seconds, Mrays/s (single rays and packets), work
/// per ray (counters), memory, and error against the exact reference
/// (ExactTracer) on a subset of the rays, in the vocabulary of `bsprt compare`
/// (include/bsprt/compare.h, formats.md). Reports as Markdown, CSV and JSON
/// (bench_report.h). Prints nothing: progress goes through a callback.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "bsprt/compare.h"
#include "bsprt/ray.h"
#include "traverse/counters.h"
#include "traverse/accelerator.h"
#include "geometry/core/triangle_soup.h"
#include "geometry/io/camera_file.h"
#include "bsprt/vec3.h"

namespace bsprt {

/// A scene to benchmark: a mesh file, the embedded default scene, or a
/// generated closed icosphere ("icosphere:L", 20·4^L triangles).
struct BenchScene {
  std::string name;  ///< short name used in tables (file stem, "default", "icosphere-L")
  TriangleSoup soup;
  /// A ball strictly inside a closed surface, when known (generated
  /// icospheres): the "inside" ray set starts there, so every ray must hit and
  /// a lost hit is a leak.
  std::optional<std::pair<Vec3f, float>> inside_ball;
};

/// Loads a scene spec: a mesh path, "default", "icosphere:L" (L = 0..9), or
/// "twin:SPEC" (SPEC's triangles listed twice, the copies reversed; named
/// "NAME-twins").
/// Throws InputError / UsageError on bad input.
BenchScene load_bench_scene(const std::string& spec);

/// What to run; the defaults are those of `bsprt bench`.
struct BenchOptions {
  /// Ray sets: primary (camera framing the scene, 8x8-pixel tiles so packets
  /// are coherent), random, vertex, edge (geometry/ray_gen.h), inside
  /// (only scenes with an inside ball; skipped elsewhere).
  std::vector<std::string> ray_sets = {"primary", "random", "vertex", "edge"};
  /// Accelerator names of make_tracer (builder/accel_factory.h).
  std::vector<std::string> modes = {"kd", "bsp", "bsp-zero-eps", "bsp-certified", "embree", "embree-fast"};
  std::size_t count = 262144;      ///< rays per set for speed and counters
  std::size_t error_count = 20000;  ///< rays per set checked against the exact reference (0 = no error part)
  int threads = 0;                  ///< worker threads for every mode (0 = all cores)
  int runs = 2;                     ///< timing rounds: each times every mode once; a mode's fastest counts
  std::uint64_t seed = 1;           ///< ray-set seed
  /// Cameras by scene (bench --cameras FILE, geometry/io/camera_file.h): a
  /// scene with one traces its primary rays from it (e.g. sponza's atrium),
  /// the others from a camera framing the scene.
  std::vector<NamedCamera> cameras;
  /// Called as work advances: (what is being done, steps done, steps total).
  std::function<void(const std::string&, std::size_t, std::size_t)> progress;
};

/// One row: a mode on one scene's ray set.
struct BenchRow {
  std::string scene;
  std::size_t triangles = 0;
  std::string ray_set;
  std::string mode;
  std::size_t rays = 0;           ///< rays timed and counted
  double build_seconds = 0.0;     ///< build (and flatten) wall time; BSP modes share one build
  double mrays_single = 0.0;      ///< single rays, all threads
  double mrays_packet = 0.0;      ///< packets of `packet_width` (0 when the mode has none)
  int packet_width = 1;           ///< widest ISA's width; 1 for certified modes
  // Work per ray is counted on the error subset (all timed rays when there is none).
  double kd_visits = 0.0;         ///< kd node visits per ray
  double bsp_visits = 0.0;        ///< general-plane node visits per ray
  double leaf_visits = 0.0;       ///< leaves per ray
  double triangle_tests = 0.0;    ///< triangle tests per ray
  double box_visits = 0.0;        ///< box nodes per ray (bsp-top's box top, the BVH8)
  // Exact leaf tests (docs/exact-leaf-test.md), per ray: decisions a rule on
  // exact zeros made, decisions made in exact arithmetic (CGAL::Mpzf), and
  // the share of rays with at least one of those (the heaviest stage).
  double rule_decisions = 0.0;
  double exact_decisions = 0.0;
  double exact_rays = 0.0;
  std::size_t memory_bytes = 0;   ///< bytes of the structure
  std::size_t error_rays = 0;     ///< rays compared with the exact reference (0 = not measured)
  HitComparison error;            ///< lost, extra, farther (leaks), nearer, max t ulps
  double median_t_ulps = 0.0;     ///< median |t - t_exact| in ulps over rays both hit
  std::size_t hits = 0;           ///< rays of the timed set that hit
};

/// The whole run: rows plus the context the report states.
struct BenchResult {
  std::vector<BenchRow> rows;
  int threads = 0;               ///< threads actually used
  std::string isa;               ///< widest ISA detected ("avx2", ...)
  int packet_width = 1;          ///< its packet width
  std::vector<std::string> notes;  ///< what was skipped and why
};

/// Runs the benchmark. Throws UsageError for unknown modes or ray sets.
/// Throws UsageError for a mode or ray set that is unknown or listed twice,
/// or counts out of range; run_bench calls it first, `bsprt bench` before it
/// loads a scene or makes the output directory.
void check_bench_options(const BenchOptions& options);
BenchResult run_bench(const std::vector<BenchScene>& scenes, const BenchOptions& options);

/// Traces all rays with `width`-wide packets over blocks of 1024 on all
/// threads of the current arena; returns seconds of the fastest of `runs`.
/// Shared by `bsprt bench` and bench/bench_kd.cpp.
double time_trace(const Accelerator& tracer, const std::vector<Ray>& rays, std::vector<Hit>& hits, int width, int runs);

/// Work per ray, counted in a separate single-ray pass (counters cost time).
RayCounters count_work(const Accelerator& tracer, const std::vector<Ray>& rays);

/// True for modes traced only as single rays (their leaves decide exactly).
bool bench_mode_is_certified(const std::string& mode);

/// Median of |a[i] - b[i]| in ulps over rays where both hit (0 if none).
double median_t_ulps(const std::vector<Hit>& reference, const std::vector<Hit>& tested);

}  // namespace bsprt
