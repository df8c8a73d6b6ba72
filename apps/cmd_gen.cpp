// `bsprt gen SCENE -o OUT.obj [--rays KIND -n N --rays-out OUT.rays]`: writes a
// stiff scene of geometry/stiff_scenes.h as OBJ (every float printed with 9
// significant digits, so it reads back bit for bit and triangle numbers are
// kept) and, optionally, one of its stiff ray sets (geometry/stiff_rays.h).
#include <fmt/core.h>
#include <fmt/os.h>

#include <memory>

#include "apps/cli_common.h"
#include "bsprt/error.h"
#include "bsprt/io.h"
#include "geometry/scenes/stiff_rays.h"
#include "geometry/scenes/stiff_scenes.h"

namespace bsprt::cli {
namespace {

struct GenArgs {
  std::string scene, output, rays, rays_output;
  int detail = 0;
  std::size_t count = 10000;
  std::uint64_t seed = 1;
  bool list = false;
};

/// Writes `soup` as OBJ: all vertices, then one face per triangle in order.
void write_obj(const std::string& path, const TriangleSoup& soup, const std::string& comment) {
  try {
    auto out = fmt::output_file(path);
    out.print("# bsprt gen: {}\n", comment);
    for (const Vec3f& v : soup.vertices) out.print("v {:.9g} {:.9g} {:.9g}\n", v.x, v.y, v.z);
    for (const TriIndices& t : soup.triangles) out.print("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
  } catch (const std::system_error& e) {
    throw InputError(path, std::string("cannot be written: ") + e.what());
  }
}

void run(const GenArgs& a) {
  if (a.list) {
    for (const std::string& n : stiff_scene_names()) fmt::print("{:<12} {}\n", n, make_stiff_scene(n).description);
    return;
  }
  if (a.scene.empty()) throw UsageError("gen needs a SCENE name (see bsprt gen --list)");
  if (a.output.empty() && a.rays_output.empty()) throw UsageError("gen needs -o OUT.obj and/or --rays-out OUT.rays");
  const StiffScene sc = make_stiff_scene(a.scene, a.detail);
  if (!a.output.empty()) {
    write_obj(a.output, sc.soup, sc.description);
    fmt::print("wrote {} ({} triangles, {} degenerate) to {}\n", sc.name, sc.soup.size(),
               sc.soup.degenerate_count(), a.output);
  }
  if (a.rays_output.empty()) return;
  std::vector<Ray> rays;
  if (a.rays == "inside") {
    if (!sc.closed) throw UsageError("scene '" + sc.name + "' is not closed: no inside rays");
    rays = inside_rays(sc.soup, sc.inside, sc.inside_radius, a.count, a.seed);
  } else {
    rays = stiff_rays(parse_stiff_ray_kind(a.rays), sc.soup, a.count, a.seed);
  }
  write_rays(a.rays_output, rays);
  fmt::print("wrote {} {} rays to {}\n", rays.size(), a.rays, a.rays_output);
}

}  // namespace

void register_gen(CLI::App& app) {
  auto args = std::make_shared<GenArgs>();
  CLI::App* cmd = app.add_subcommand("gen", "write a stiff test scene (OBJ) and/or one of its stiff ray sets");
  cmd->add_option("SCENE", args->scene, "stiff scene name (--list shows them)");
  cmd->add_option("-o,--output", args->output, "OBJ file to write")->check(output_file());
  cmd->add_option("--detail", args->detail, "tessellation level of the solids, 0..4")->capture_default_str();
  cmd->add_option("--rays", args->rays,
                  "with --rays-out: vertex | edge | along-edge | grazing | axis-plane | axis-parallel | invalid | inside")
      ->default_val("vertex")
      ->check(CLI::IsMember({"vertex", "edge", "along-edge", "grazing", "axis-plane", "axis-parallel", "invalid",
                             "inside"}));
  cmd->add_option("--rays-out", args->rays_output, ".rays file to write")->check(output_file());
  cmd->add_option("-n,--count", args->count, "number of rays")->capture_default_str()->check(integer_in(1, kMaxRays));
  cmd->add_option("--seed", args->seed, "random seed")->capture_default_str();
  cmd->add_flag("--list", args->list, "list the stiff scenes");
  cmd->callback([args, cmd] {
    // Ray options without a .rays file to write would be ignored.
    if (args->rays_output.empty()) reject_given(*cmd, {"--rays", "--count", "--seed"}, "ray options need --rays-out");
    // These scenes are fixed lists of triangles: a detail level would be ignored.
    if (args->scene == "slivers" || args->scene == "degenerate" || args->scene == "stacks")
      reject_given(*cmd, {"--detail"}, "scene '" + args->scene + "' has no tessellation level");
    run(*args);
  });
}

}  // namespace bsprt::cli
