// `bsprt gen-rays SCENE -o RAYS`: writes a ray set (primary, random, vertex- or
// edge-aimed) so every tool, Embree included, traces the same rays.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "apps/cli_common.h"
#include "geometry/io/camera_file.h"
#include "geometry/scenes/default_scene.h"
#include "geometry/scenes/ray_gen.h"
#include "bsprt/io.h"

namespace bsprt::cli {
namespace {

struct GenRaysArgs {
  std::string scene, output, kind = "random";
  std::size_t count = 1'000'000;
  std::uint64_t seed = 1;
  std::vector<int> size;
  std::string camera;  ///< primary rays: --camera FILE[:NAME] instead of framing the scene
  bool allow_nonfinite = false;
  bool count_given = false;  ///< -n was on the command line
};

void run(const GenRaysArgs& a) {
  const RaySetKind kind = parse_ray_set(a.kind);
  if (kind != RaySetKind::Primary && (!a.camera.empty() || !a.size.empty()))
    throw UsageError(std::string(!a.camera.empty() ? "--camera" : "--size") + " is for --kind primary, not " + a.kind);
  if (!a.size.empty() && a.count_given)
    throw UsageError("-n and --size both set the number of primary rays: give one");
  const TriangleSoup soup = load_scene(a.scene, a.allow_nonfinite, true);
  std::vector<Ray> rays;
  // Every primary set takes its camera here, -n too: through make_rays the
  // default scene was framed instead of seen from its own view (review of 2026-12-07).
  if (kind == RaySetKind::Primary) {
    const bool is_default = a.scene.empty() || a.scene == "default";
    const Camera cam = !a.camera.empty() ? camera_from_spec(a.camera).camera
                       : is_default      ? default_scene_camera()
                                         : frame_bounds(soup.bounds());
    const int side = std::max(1, int(std::lround(std::sqrt(double(a.count)))));
    rays = primary_rays(cam, a.size.empty() ? side : a.size[0], a.size.empty() ? side : a.size[1]);
  } else {
    rays = make_rays(kind, soup, a.count, a.seed);
  }
  write_rays(a.output, rays);
  fmt::print("wrote {} {} rays to {}\n", rays.size(), a.kind, a.output);
}

}  // namespace

void register_gen_rays(CLI::App& app) {
  auto args = std::make_shared<GenRaysArgs>();
  CLI::App* cmd = app.add_subcommand("gen-rays", "write a .rays file: primary, random, vertex- or edge-aimed rays");
  cmd->add_option("SCENE", args->scene, kSceneHelp)->required();
  cmd->add_option("-o,--output", args->output, ".rays file to write")->required()->check(output_file());
  cmd->add_option("--kind", args->kind, "primary | random | vertex | edge")->capture_default_str();
  cmd->add_option("-n,--count", args->count, "number of rays (primary: about n pixels, square)")
      ->capture_default_str()->check(integer_in(1, kMaxRays));
  cmd->add_option("--camera", args->camera, "primary rays: camera file FILE or FILE:NAME (docs/rendering.md)")
      ->check(non_empty_path());
  cmd->add_option("--size", args->size, "primary rays: image width and height (camera frames the scene)")
      ->expected(2)->check(integer_in(1, kMaxImageSide));
  cmd->add_option("--seed", args->seed, "random seed")->capture_default_str();
  cmd->add_flag("--allow-nonfinite", args->allow_nonfinite, "keep triangles with NaN/Inf corners (flagged degenerate)");
  cmd->callback([args, cmd] {
    args->count_given = cmd->count("--count") > 0;
    // Primary rays come from the camera alone: a seed would be ignored.
    if (args->kind == "primary") reject_given(*cmd, {"--seed"}, "primary rays are not random");
    run(*args);
  });
}

}  // namespace bsprt::cli
