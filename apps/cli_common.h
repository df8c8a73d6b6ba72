#pragma once
/// \file cli_common.h
/// What the `bsprt` subcommands share: loading a scene (or the embedded default
/// one), the --accel/--tree/--threads options, a TBB thread cap.

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "builder/accel_factory.h"
#include "geometry/io/load_mesh.h"
#include "geometry/core/triangle_soup.h"

namespace bsprt::cli {

/// Options every tracing subcommand takes.
struct TraceOptions {
  std::string accel = "embree";
  std::string tree;
  int threads = 0;
  int packets = 1;
  bool allow_nonfinite = false;
  std::string membership = "area";
  std::uint32_t top_slots = 0;  ///< 0: the accelerator's default (AccelOptions::top_slots)
  std::string single_rays = "auto";
};

/// Option validators with plain messages ("must be a number > 0, not 'x'"):
/// CLI11's own print their bounds with 300 digits, let NaN through and let an
/// unsigned option wrap "-5" around. Each parses the text as a number first.
/// number_above(lo): a number > lo; number_at_least(lo): >= lo; number_below
/// (hi) adds x < hi; integer_in(lo, hi): an integer in [lo, hi].
CLI::Validator number_above(double lo);
CLI::Validator number_at_least(double lo);
CLI::Validator number_in_open(double lo, double hi);
CLI::Validator integer_in(long long lo, long long hi);
/// A path option given as an empty string (it would mean "not given").
CLI::Validator non_empty_path();
/// A file to write: not empty, not a directory, in a folder that exists,
/// checked when the command line is parsed, before any work (an -o naming a
/// directory failed only after the build and the trace; review of 2026-12-07).
CLI::Validator output_file();

/// Largest ray count `gen-rays -n` writes (32 GB of rays), and largest image
/// side of --size: past these a run fails for memory, not for a reason a
/// message could name.
inline constexpr long long kMaxRays = 1'000'000'000;
inline constexpr long long kMaxImageSide = 16384;

/// Throws UsageError when an option of `cmd` named in `names` was given:
/// `why` says what they are for ("--spp is for --mode path").
void reject_given(const CLI::App& cmd, const std::vector<std::string>& names, const std::string& why);

/// Adds --accel, --tree, --threads, --packets, --membership, --top-slots,
/// --single-rays, --allow-nonfinite to `cmd`.
void add_trace_options(CLI::App& cmd, TraceOptions& o, const std::string& default_accel);

/// Scene spec prefix: "twin:FILE" is FILE with every triangle listed twice,
/// the copy with reversed winding (with_reversed_copies).
inline constexpr std::string_view kTwinPrefix = "twin:";
/// Help text of a SCENE argument that load_scene reads.
inline constexpr const char* kSceneHelp =
    "mesh file (obj, ply, off, stl), 'default', or twin:FILE (FILE with every triangle listed twice, the copy "
    "reversed)";

/// Loads SCENE, or the embedded default scene when `path` is "default", or
/// "twin:SCENE" (kTwinPrefix); prints a one-line load summary to stderr when
/// `verbose`. An empty `path` is a UsageError (it is not "default").
TriangleSoup load_scene(const std::string& path, bool allow_nonfinite, bool verbose);

/// "area" or "closed" (BspMembership); throws UsageError otherwise.
BspMembership parse_membership(const std::string& name);

/// Caps TBB's worker threads for the life of the returned object (0 = all cores).
std::unique_ptr<tbb::global_control> limit_threads(int threads);

/// The options given a non-default value in `o` that `o.accel` would not use,
/// each with the accelerators it is for; empty when all apply.
std::vector<std::string> ignored_options(const TraceOptions& o);

/// `o` with the options ignored_options() lists set back to their defaults
/// (render --heat-compare hands the first accelerator's options to a second one).
TraceOptions without_ignored_options(TraceOptions o);

/// Builds or loads the accelerator named in `o`, with a progress bar on a
/// terminal; throws UsageError when an option given is one `o.accel` ignores.
std::unique_ptr<Accelerator> make_accel(const TraceOptions& o, const TriangleSoup& soup);

/// Registration of each subcommand (one file each).
void register_trace(CLI::App& app);
void register_render(CLI::App& app);
void register_info(CLI::App& app);
void register_inside(CLI::App& app);
void register_gen_rays(CLI::App& app);
void register_compare(CLI::App& app);
void register_build(CLI::App& app);  // build and stats
void register_bench(CLI::App& app);
void register_gen(CLI::App& app);  // stiff scenes and rays
void register_verify(CLI::App& app);  // exact certificate of a BSP tree file

/// Thrown by `compare` when the files disagree: exit code 1, nothing more printed.
struct CompareFailed {};

}  // namespace bsprt::cli
