// `bsprt render [SCENE] -o out.png`: ray-casts a scene (the embedded default
// scene when none is given) with eye-light shading into a PNG.
#include <fmt/core.h>

#include <memory>

#include "apps/cli_common.h"
#include "apps/progress.h"
#include "apps/render.h"
#include "geometry/default_scene.h"

namespace bsprt::cli {
namespace {

struct RenderArgs {
  std::string scene, output = "bsprt.png";
  TraceOptions trace;
  std::vector<int> size{800, 600};
  std::vector<float> vp, vi, vu;
  float fov = 0.0f;
  bool stats = false;
};

Vec3f to_vec(const std::vector<float>& v) { return {v[0], v[1], v[2]}; }

Camera pick_camera(const RenderArgs& a, const TriangleSoup& soup) {
  const bool is_default = a.scene.empty() || a.scene == "default";
  Camera cam = is_default ? default_scene_camera() : frame_bounds(soup.bounds());
  if (!a.vp.empty()) cam.vp = to_vec(a.vp);
  if (!a.vi.empty()) cam.vi = to_vec(a.vi);
  if (!a.vu.empty()) cam.vu = to_vec(a.vu);
  if (a.fov > 0) cam.fov = a.fov;
  return cam;
}

void run(const RenderArgs& a) {
  const auto threads = limit_threads(a.trace.threads);
  const TriangleSoup soup = load_scene(a.scene, a.trace.allow_nonfinite, true);
  const std::unique_ptr<Tracer> tracer = make_accel(a.trace, soup);
  RenderOptions options;
  options.width = a.size[0];
  options.height = a.size[1];
  options.camera = pick_camera(a, soup);
  options.packet_width = a.trace.packets;
  RenderStats stats;
  Image image;
  {
    const std::uint64_t tiles = std::uint64_t((options.width + 15) / 16) * std::uint64_t((options.height + 15) / 16);
    ProgressBar bar("rendering", tiles, "tiles", ProgressBar::stderr_is_terminal());
    image = render_cast(*tracer, soup, options, &stats, [&](std::uint64_t done, std::uint64_t) { bar.set(done); });
  }
  write_png(a.output, image);
  fmt::print("rendered {}x{} with {} in {:.3f} s ({:.2f} Mrays/s, {} of {} rays hit) -> {}\n", options.width,
             options.height, tracer->name(), stats.seconds, stats.rays / stats.seconds * 1e-6, stats.hits,
             stats.rays, a.output);
  if (a.stats) {
    const double n = double(stats.rays);
    fmt::print("per ray: {:.3f} kd node visits, {:.3f} BSP node visits, {:.3f} leaf visits, {:.3f} triangle tests\n",
               stats.counters.kd_node_visits / n, stats.counters.bsp_node_visits / n,
               stats.counters.leaf_visits / n, stats.counters.triangle_tests / n);
  }
}

}  // namespace

void register_render(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "ray-cast a scene into a PNG (eye-light shading)");
  cmd->add_option("SCENE", args->scene, "mesh file, or omit / 'default' for the embedded default scene");
  cmd->add_option("-o,--output", args->output, "PNG file to write")->capture_default_str();
  cmd->add_option("--size", args->size, "image width and height")->expected(2)->capture_default_str();
  cmd->add_option("--vp", args->vp, "camera position X Y Z")->expected(3);
  cmd->add_option("--vi", args->vi, "camera look-at point X Y Z")->expected(3);
  cmd->add_option("--vu", args->vu, "camera up vector X Y Z")->expected(3);
  cmd->add_option("--fov", args->fov, "vertical field of view in degrees");
  cmd->add_flag("--stats", args->stats, "count and print node visits and triangle tests per ray");
  add_trace_options(*cmd, args->trace, "embree");
  cmd->callback([args] { run(*args); });
}

}  // namespace bsprt::cli
