// `bsprt inside SCENE POINTS -o OUT`: inside, outside or on the surface of a
// closed mesh, for each point of a text file, exactly (robust/inside_query.h).
#include <fmt/core.h>
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>
#include <system_error>
#include <vector>

#include "apps/cli_common.h"
#include "apps/progress.h"
#include "bsprt/error.h"
#include "geometry/core/fp_env.h"
#include "geometry/core/read_file.h"
#include "robust/inside_query.h"

namespace bsprt::cli {
namespace {

struct InsideArgs {
  std::string scene, points, output;
  bool allow_nonfinite = false;
  int threads = 0;
};

/// The points of a points file, and how many of them were rounded.
struct Points {
  std::vector<Vec3f> at;
  std::size_t rounded = 0;  ///< points with a coordinate that is not a float, read as the nearest one
};

/// `line` with bytes that would garble a terminal (NUL, control characters)
/// shown as '?', for messages.
std::string printable(const std::string& line) {
  std::string out = line;
  for (char& ch : out)
    if (static_cast<unsigned char>(ch) < 0x20 && ch != '\t') ch = '?';
  return out;
}

/// Points from a text file: "x y z" per line; empty lines and '#' comments
/// (a whole line, or the rest of one) are skipped. A coordinate is read as a
/// double and rounded to the nearest float, as mesh coordinates are (the
/// query is exact on float points; docs/exact-leaf-test.md, "Inside
/// queries"): the rounded points are counted. A line that is not three
/// numbers, a number that is not finite or overflows float, is an InputError
/// naming the file and line.
Points read_points(const std::string& path) {
  const std::string text = read_file_bytes(path, "points file");
  Points points;
  std::size_t n = 0;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::string line = text.substr(at, end - at);
    at = end + 1;
    ++n;
    const std::string data = line.substr(0, line.find('#'));
    std::istringstream s(data);
    std::string word[3], rest;
    if (data.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (!(s >> word[0] >> word[1] >> word[2]) || (s >> rest))
      throw InputError(path, std::int64_t(n), "expected three numbers \"x y z\", got \"" + printable(line) + "\"");
    Vec3f p;
    bool rounded = false;
    for (int k = 0; k < 3; ++k) {
      double v = 0.0;
      // A leading '+' as mesh files allow it (from_chars does not).
      const char* first = word[k].data() + (word[k].size() > 1 && word[k][0] == '+' && word[k][1] != '-' ? 1 : 0);
      const char* last = word[k].data() + word[k].size();
      auto [ptr, ec] = std::from_chars(first, last, v);
      if (ec == std::errc::result_out_of_range && ptr == last) {
        // Out of double's range: beyond it is an overflow; below it (1e-400)
        // the nearest float is 0 or a subnormal, a rounding like any other.
        const double d = std::strtod(std::string(first, last).c_str(), nullptr);
        if (std::isinf(d))
          throw InputError(path, std::int64_t(n), "\"" + printable(word[k]) + "\" overflows float (points are float)");
        v = d, ec = std::errc{};
        rounded = true;  // the file's value is not 0, nor this subnormal
      }
      if (ec == std::errc{} && std::isfinite(v) && !std::isfinite(float(v)))
        throw InputError(path, std::int64_t(n), "\"" + printable(word[k]) + "\" overflows float (points are float)");
      if (ec != std::errc{} || ptr != last)
        throw InputError(path, std::int64_t(n), "\"" + printable(word[k]) + "\" is not a number");
      if (!std::isfinite(v)) throw InputError(path, std::int64_t(n), "\"" + printable(word[k]) + "\" is not finite");
      p[k] = float(v);
      rounded = rounded || double(p[k]) != v;
    }
    points.at.push_back(p);
    points.rounded += rounded;
  }
  return points;
}

void run(const InsideArgs& a) {
  const TriangleSoup soup = load_scene(a.scene, a.allow_nonfinite, true);
  const Points read = read_points(a.points);
  const std::vector<Vec3f>& points = read.at;
  if (const std::size_t bad = open_or_inconsistent_edges(soup))
    fmt::print(stderr,
               "warning: {} edges of the mesh are open, non-manifold or inconsistently oriented: inside and "
               "outside by parity are not well defined there\n",
               bad);
  const auto cap = limit_threads(a.threads);
  const auto t0 = std::chrono::steady_clock::now();
  const InsideQuery query(soup);
  std::vector<PointSide> sides(points.size());
  tbb::combinable<RayCounters> counters;
  ProgressBar bar("inside", points.size(), "points", ProgressBar::stderr_is_terminal() && points.size() > 10000);
  IeeeTasks ieee;  // IEEE arithmetic in every task (geometry/core/fp_env.h)
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 1024), [&](const auto& r) {
    RayCounters& c = counters.local();
    for (std::size_t i = r.begin(); i < r.end(); ++i) sides[i] = query.side(points[i], &c);
    bar.advance(r.size());
  }, ieee.context());
  bar.set(points.size());
  bar.finish();
  const RayCounters c = counters.combine([](RayCounters x, const RayCounters& y) { return x += y; });
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ofstream out(a.output);
  if (!out) throw InputError(a.output, "cannot write");
  std::size_t count[3] = {0, 0, 0};
  for (const PointSide side : sides) {
    out << point_side_name(side) << '\n';
    ++count[int(side)];
  }
  if (!out) throw InputError(a.output, "write failed");
  fmt::print("{} points{}: {} inside, {} outside, {} on the surface ({:.3f} s; {:.2f} candidate triangles and {:.4f} "
             "exact decisions per point); wrote {}\n",
             points.size(),
             read.rounded ? fmt::format(" ({} with a coordinate rounded to the nearest float, as mesh coordinates are)",
                                        read.rounded)
                          : std::string(),
             count[int(PointSide::Inside)], count[int(PointSide::Outside)],
             count[int(PointSide::OnSurface)], s, points.empty() ? 0.0 : double(c.triangle_tests) / points.size(),
             points.empty() ? 0.0 : double(c.exact_decisions) / points.size(), a.output);
}

}  // namespace

void register_inside(CLI::App& app) {
  auto args = std::make_shared<InsideArgs>();
  CLI::App* cmd = app.add_subcommand(
      "inside", "inside, outside or on the surface of a closed mesh, exactly, for each point of a text file");
  cmd->add_option("SCENE", args->scene, "closed mesh file or 'default'")->required();
  cmd->add_option("POINTS", args->points,
                  "text file: one point \"x y z\" per line ('#' comments), each coordinate read as the nearest float")
      ->required();
  cmd->add_option("-o,--output", args->output, "text file: inside, outside or surface, a line per point")->required()->check(output_file());
  cmd->add_flag("--allow-nonfinite", args->allow_nonfinite, "keep triangles with NaN/Inf corners (flagged degenerate)");
  cmd->add_option("--threads", args->threads, "worker threads (0 = all cores); the answers do not depend on it")
      ->check(integer_in(0, kMaxThreads));
  cmd->callback([args] { run(*args); });
}

}  // namespace bsprt::cli
