// `bsprt inside SCENE POINTS -o OUT`: inside, outside or on the surface of a
// closed mesh, for each point of a text file, exactly (robust/inside_query.h).
#include <fmt/core.h>

#include <chrono>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include "apps/cli_common.h"
#include "apps/progress.h"
#include "bsprt/error.h"
#include "robust/inside_query.h"

namespace bsprt::cli {
namespace {

struct InsideArgs {
  std::string scene, points, output;
  bool allow_nonfinite = false;
};

/// Points from a text file: "x y z" per line; empty lines and lines starting
/// with '#' are skipped. A line that is not three numbers is an InputError
/// naming the file and line.
std::vector<Vec3f> read_points(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open");
  std::vector<Vec3f> points;
  std::string line;
  for (std::size_t n = 1; std::getline(in, line); ++n) {
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream s(line);
    Vec3f p;
    std::string rest;
    if (!(s >> p.x >> p.y >> p.z) || (s >> rest))
      throw InputError(path + ":" + std::to_string(n), "expected three numbers \"x y z\", got \"" + line + "\"");
    points.push_back(p);
  }
  return points;
}

void run(const InsideArgs& a) {
  const TriangleSoup soup = load_scene(a.scene, a.allow_nonfinite, true);
  const std::vector<Vec3f> points = read_points(a.points);
  if (const std::size_t bad = open_or_inconsistent_edges(soup))
    fmt::print(stderr,
               "warning: {} edges of the mesh are open, non-manifold or inconsistently oriented: inside and "
               "outside by parity are not well defined there\n",
               bad);
  const auto t0 = std::chrono::steady_clock::now();
  const InsideQuery query(soup);
  std::vector<PointSide> sides(points.size());
  RayCounters c;
  ProgressBar bar("inside", points.size(), "points", ProgressBar::stderr_is_terminal() && points.size() > 10000);
  for (std::size_t i = 0; i < points.size(); ++i) {
    sides[i] = query.side(points[i], &c);
    if ((i & 1023) == 1023) bar.advance(1024);
  }
  bar.set(points.size());
  bar.finish();
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ofstream out(a.output);
  if (!out) throw InputError(a.output, "cannot write");
  std::size_t count[3] = {0, 0, 0};
  for (const PointSide side : sides) {
    out << point_side_name(side) << '\n';
    ++count[int(side)];
  }
  if (!out) throw InputError(a.output, "write failed");
  fmt::print("{} points: {} inside, {} outside, {} on the surface ({:.3f} s; {:.2f} candidate triangles and {:.4f} "
             "exact decisions per point); wrote {}\n",
             points.size(), count[int(PointSide::Inside)], count[int(PointSide::Outside)],
             count[int(PointSide::OnSurface)], s, points.empty() ? 0.0 : double(c.triangle_tests) / points.size(),
             points.empty() ? 0.0 : double(c.exact_decisions) / points.size(), a.output);
}

}  // namespace

void register_inside(CLI::App& app) {
  auto args = std::make_shared<InsideArgs>();
  CLI::App* cmd = app.add_subcommand(
      "inside", "inside, outside or on the surface of a closed mesh, exactly, for each point of a text file");
  cmd->add_option("SCENE", args->scene, "closed mesh file or 'default'")->required();
  cmd->add_option("POINTS", args->points, "text file: one point \"x y z\" per line ('#' comments)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output, "text file: inside, outside or surface, a line per point")->required();
  cmd->add_flag("--allow-nonfinite", args->allow_nonfinite, "keep triangles with NaN/Inf corners (flagged degenerate)");
  cmd->callback([args] { run(*args); });
}

}  // namespace bsprt::cli
