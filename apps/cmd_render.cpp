// `bsprt render [SCENE] -o out.png --mode cast|path|heat`: ray casting with
// packets, path tracing with single rays, and per-pixel cost heat maps, on any
// accelerator (the embedded default scene when none is given).
#include <fmt/core.h>

#include <filesystem>
#include <fstream>
#include <memory>

#include "apps/cli_common.h"
#include "apps/heat_map.h"
#include "apps/path_tracer.h"
#include "apps/progress.h"
#include "apps/render.h"
#include "geometry/io/camera_file.h"
#include "geometry/scenes/default_scene.h"
#include "bsprt/error.h"

namespace bsprt::cli {
namespace {

struct RenderArgs {
  std::string scene = "default", output = "bsprt.png", mode = "cast", json;
  TraceOptions trace;
  std::vector<int> size{800, 600};
  std::vector<float> vp, vi, vu;
  float fov = 0.0f;
  std::string camera;  ///< --camera FILE[:NAME]; --vp/--vi/--vu/--fov override its fields
  bool stats = false;
  int spp = 16, bounces = 3;
  std::uint64_t seed = 1;
  std::string heat_metric = "nodes", heat_compare;
  float heat_max = 0.0f;
};

Vec3f to_vec(const std::vector<float>& v) { return {v[0], v[1], v[2]}; }

Camera pick_camera(const RenderArgs& a, const TriangleSoup& soup) {
  const bool is_default = a.scene == "default";
  const bool placed = !a.vp.empty() && !a.vi.empty();  // the options alone place the camera: no framing
  Camera cam;
  if (!a.camera.empty()) {
    const NamedCamera named = camera_from_spec(a.camera);
    const std::string file = std::filesystem::path(a.scene).filename().string();
    if (!named.scene.empty() && named.scene != file)
      fmt::print(stderr, "render: warning: camera '{}' is for {}, not {}\n", named.name, named.scene,
                 is_default ? "the default scene" : file);
    cam = named.camera;
  } else if (is_default) {
    cam = default_scene_camera();
  } else if (placed) {
    cam.fov = 45.0f;  // frame_bounds' field of view
  } else {
    cam = frame_bounds(soup.bounds());
  }
  if (!a.vp.empty()) cam.vp = to_vec(a.vp);
  if (!a.vi.empty()) cam.vi = to_vec(a.vi);
  if (!a.vu.empty()) cam.vu = to_vec(a.vu);
  if (a.fov > 0) cam.fov = a.fov;
  if (const std::string problem = camera_problem(cam); !problem.empty())
    throw UsageError("the camera cannot see anything: " + problem);
  return cam;
}

/// .png or .pfm, by the extension of `path` (checked before any work, check_output).
void write_image(const std::string& path, const Image& image) {
  if (path.size() > 4 && path.substr(path.size() - 4) == ".pfm") write_pfm(path, image);
  else write_png(path, image);
}

/// The image file must end in .png or .pfm, the two formats render writes.
void check_output(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext != ".png" && ext != ".pfm")
    throw UsageError("-o " + path + ": render writes .png or .pfm images, not '" +
                     (ext.empty() ? "(no extension)" : ext) + "'");
}

std::uint64_t tile_count(int w, int h) { return std::uint64_t((w + 15) / 16) * std::uint64_t((h + 15) / 16); }

void run_cast(const RenderArgs& a, const Accelerator& tracer, const TriangleSoup& soup, RenderOptions options) {
  RenderStats stats;
  Image image;
  {
    ProgressBar bar("rendering", tile_count(options.width, options.height), "tiles", ProgressBar::stderr_is_terminal());
    image = render_cast(tracer, soup, options, &stats, [&](std::uint64_t done, std::uint64_t) { bar.set(done); });
  }
  write_image(a.output, image);
  fmt::print("cast {}x{} with {} in {:.3f} s ({:.2f} Mrays/s, {} of {} rays hit) -> {}\n", options.width,
             options.height, tracer.name(), stats.seconds, stats.rays / stats.seconds * 1e-6, stats.hits, stats.rays,
             a.output);
  if (a.stats) {
    const double n = double(stats.rays);
    fmt::print("per ray: {:.3f} kd node visits, {:.3f} BSP node visits, {:.3f} leaf visits, {:.3f} triangle tests\n",
               stats.counters.kd_node_visits / n, stats.counters.bsp_node_visits / n,
               stats.counters.leaf_visits / n, stats.counters.triangle_tests / n);
  }
}

void run_path(const RenderArgs& a, const Accelerator& tracer, const TriangleSoup& soup, const RenderOptions& base) {
  PathOptions options;
  options.width = base.width, options.height = base.height, options.camera = base.camera;
  options.spp = a.spp, options.bounces = a.bounces, options.seed = a.seed, options.packet_width = base.packet_width;
  options.count = a.stats;
  PathStats stats;
  Image image;
  {
    ProgressBar bar(fmt::format("path tracing ({} spp)", a.spp), tile_count(options.width, options.height), "tiles",
                    ProgressBar::stderr_is_terminal());
    image = render_path(tracer, soup, options, &stats, [&](std::uint64_t done, std::uint64_t) { bar.set(done); });
  }
  write_image(a.output, image);
  fmt::print("path {}x{} {} spp {} bounces with {} in {:.3f} s, {} rays, {} NaN pixels -> {}\n", options.width,
             options.height, options.spp, options.bounces, tracer.name(), stats.seconds, stats.rays, stats.nan_pixels,
             a.output);
  std::string json = fmt::format("{{\"accel\": \"{}\", \"mode\": \"path\", \"width\": {}, \"height\": {}, \"spp\": {}, "
                                 "\"bounces\": {}, \"seed\": {}, \"seconds\": {:.6f}, \"rays\": {}, \"nan_pixels\": {}, "
                                 "\"counted\": {}, \"by_bounce\": [",
                                 tracer.name(), options.width, options.height, options.spp, options.bounces,
                                 options.seed, stats.seconds, stats.rays, stats.nan_pixels, a.stats);
  for (std::size_t b = 0; b < stats.rays_by_bounce.size(); ++b) {
    const double s = stats.trace_seconds_by_bounce[b];
    const double mrays = s > 0 ? stats.rays_by_bounce[b] / s * 1e-6 : 0.0;
    fmt::print("  bounce {}: {} rays, {:.2f} Mrays/s per thread\n", b, stats.rays_by_bounce[b], mrays);
    json += fmt::format("{}{{\"bounce\": {}, \"rays\": {}, \"trace_thread_seconds\": {:.6f}, \"mrays_per_thread_second\": {:.4f}",
                        b ? ", " : "", b, stats.rays_by_bounce[b], s, mrays);
    if (a.stats) {  // work per ray of this bounce (path and shadow rays); the timing above includes the counting
      const RayCounters& c = stats.counters_by_bounce[b];
      const double n = stats.rays_by_bounce[b] ? double(stats.rays_by_bounce[b]) : 1.0;
      fmt::print("    per ray: {:.3f} kd node visits, {:.3f} BSP node visits, {:.3f} leaf visits, {:.3f} triangle tests\n",
                 c.kd_node_visits / n, c.bsp_node_visits / n, c.leaf_visits / n, c.triangle_tests / n);
      json += fmt::format(", \"kd_node_visits\": {:.4f}, \"bsp_node_visits\": {:.4f}, \"leaf_visits\": {:.4f}, "
                          "\"triangle_tests\": {:.4f}",
                          c.kd_node_visits / n, c.bsp_node_visits / n, c.leaf_visits / n, c.triangle_tests / n);
    }
    json += "}";
  }
  json += "]}\n";
  if (!a.json.empty()) {
    std::ofstream f(a.json);
    f << json;
    f.close();
    if (!f) throw InputError(a.json, "cannot write the --json summary");
  }
}

void run_heat(const RenderArgs& a, const Accelerator& tracer, const TriangleSoup& soup, const RenderOptions& options) {
  const HeatMetric metric = parse_heat_metric(a.heat_metric);
  const std::vector<float> cost = pixel_costs(tracer, options, metric);
  Image image;
  if (!a.heat_compare.empty()) {
    TraceOptions other = a.trace;
    other.accel = a.heat_compare;
    other.tree.clear();
    const std::unique_ptr<Accelerator> b = make_accel(without_ignored_options(other), soup);
    const std::vector<float> cost_b = pixel_costs(*b, options, metric);
    image = heat_difference_image(cost, cost_b, options.width, options.height,
                                  fmt::format("{} - {}\n{}", tracer.name(), b->name(), heat_metric_name(metric)));
  } else {
    image = heat_image(cost, options.width, options.height, a.heat_max,
                       fmt::format("{}\n{}{}", tracer.name(), heat_metric_name(metric), metric == HeatMetric::Time ? " (ns)" : ""));
  }
  double sum = 0;
  for (float c : cost) sum += c;
  write_image(a.output, image);
  fmt::print("heat map ({}) of {} {}x{}: mean {:.3f} per pixel -> {}\n", heat_metric_name(metric), tracer.name(),
             options.width, options.height, sum / double(cost.size()), a.output);
}

void run(const RenderArgs& a) {
  check_output(a.output);
  if (a.mode == "heat" && parse_heat_metric(a.heat_metric) != HeatMetric::Time)
    for (const std::string& accel : {a.trace.accel, a.heat_compare})
      if (!accel.empty() && accel_info(accel).embree_domain)
        // Embree reports no counts: the map was all zeros, with exit 0 (review of 2026-12-07).
        throw UsageError("--heat-metric " + a.heat_metric + ": " + accel +
                         " does not count its node visits or triangle tests; use --heat-metric time");
  const auto threads = limit_threads(a.trace.threads);
  const TriangleSoup soup = load_scene(a.scene, a.trace.allow_nonfinite, true);
  RenderOptions options;
  options.camera = pick_camera(a, soup);  // before the build: a camera that sees nothing is refused at once
  const std::unique_ptr<Accelerator> tracer = make_accel(a.trace, soup);
  options.width = a.size[0];
  options.height = a.size[1];
  options.packet_width = a.trace.packets;
  if (a.mode == "cast") return run_cast(a, *tracer, soup, options);
  if (a.mode == "path") return run_path(a, *tracer, soup, options);
  return run_heat(a, *tracer, soup, options);  // --mode is checked by its option
}

}  // namespace

void register_render(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "render a scene: ray casting, path tracing or cost heat maps");
  cmd->add_option("SCENE", args->scene, std::string(kSceneHelp) + "; omit for the default scene");
  cmd->add_option("-o,--output", args->output, "image to write (.png, or .pfm for raw radiance)")->capture_default_str()->check(output_file());
  cmd->add_option("--mode", args->mode, "cast (eye light, packets) | path (path tracing) | heat (cost per pixel)")
      ->capture_default_str()->check(CLI::IsMember({"cast", "path", "heat"}));
  cmd->add_option("--size", args->size, "image width and height")
      ->expected(2)->capture_default_str()->check(integer_in(1, kMaxImageSide));
  cmd->add_option("--vp", args->vp, "camera position X Y Z")->expected(3);
  cmd->add_option("--vi", args->vi, "camera look-at point X Y Z")->expected(3);
  cmd->add_option("--vu", args->vu, "camera up vector X Y Z")->expected(3);
  cmd->add_option("--fov", args->fov, "vertical field of view in degrees, in (0, 180)")->check(number_in_open(0, 180));
  cmd->add_option("--camera", args->camera,
                  "camera file (docs/rendering.md), FILE or FILE:NAME, e.g. bench/cameras.json:sponza-atrium; "
                  "--vp/--vi/--vu/--fov override its fields")
      ->check(non_empty_path());
  cmd->add_flag("--stats", args->stats, "cast: count and print node visits and triangle tests per ray; path: the same per bounce, also "
                "in --json (the timings then include the counting)");
  cmd->add_option("--spp", args->spp, "path: samples per pixel")->capture_default_str()->check(integer_in(1, 1 << 20));
  cmd->add_option("--bounces", args->bounces, "path: indirect bounces (0 = direct light)")->capture_default_str()
      ->check(CLI::Range(0, 64));
  cmd->add_option("--seed", args->seed, "path: random seed (images are identical for any thread count)")
      ->capture_default_str();
  cmd->add_option("--json", args->json, "path: write a JSON summary (rays, Mrays/s by bounce) to this file")
      ->check(output_file());
  cmd->add_option("--heat-metric", args->heat_metric, "heat: time | nodes | tests")->capture_default_str();
  cmd->add_option("--heat-compare", args->heat_compare, "heat: draw the difference to this accelerator's map");
  cmd->add_option("--heat-max", args->heat_max, "heat: top of the colour scale (0 = the image's maximum)")
      ->check(number_at_least(0.0));
  add_trace_options(*cmd, args->trace, "bsp");
  cmd->callback([args, cmd] {
    // Options of one mode given with another would be ignored: refuse them.
    if (args->mode != "path") reject_given(*cmd, {"--spp", "--bounces", "--seed", "--json"}, "for --mode path only");
    if (args->mode != "heat")
      reject_given(*cmd, {"--heat-metric", "--heat-compare", "--heat-max"}, "for --mode heat only");
    // A heat map traces single rays, one at a time, and counts its own work.
    if (args->mode == "heat") reject_given(*cmd, {"--packets", "--single-rays", "--stats"}, "not used by --mode heat");
    if (!args->heat_compare.empty())
      reject_given(*cmd, {"--heat-max"}, "a difference map scales to its own largest difference");
    run(*args);
  });
}

}  // namespace bsprt::cli
