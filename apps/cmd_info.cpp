// `bsprt info SCENE`: counts, bounds and degenerate triangles of a mesh.
#include <fmt/core.h>

#include <memory>

#include "apps/cli_common.h"

namespace bsprt::cli {
namespace {

struct InfoArgs {
  std::string scene;
  bool allow_nonfinite = false;
};

void run(const InfoArgs& a) {
  const TriangleSoup soup = load_scene(a.scene, a.allow_nonfinite, true);
  const Box3f b = soup.bounds();
  fmt::print("triangles   {}\n", soup.size());
  fmt::print("vertices    {}\n", soup.vertices.size());
  fmt::print("degenerate  {}\n", soup.degenerate_count());
  fmt::print("bounds      [{}, {}, {}] .. [{}, {}, {}]\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
  const Vec3f d = b.diagonal();
  fmt::print("extent      {} x {} x {}\n", d.x, d.y, d.z);
}

}  // namespace

void register_info(CLI::App& app) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* cmd = app.add_subcommand("info", "print triangle and vertex counts, bounds and degenerate triangles");
  cmd->add_option("SCENE", args->scene, kSceneHelp)->required();
  cmd->add_flag("--allow-nonfinite", args->allow_nonfinite, "keep triangles with NaN/Inf corners (flagged degenerate)");
  cmd->callback([args] { run(*args); });
}

}  // namespace bsprt::cli
