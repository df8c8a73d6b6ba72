// The `bsprt bench` library on a tiny generated scene with few rays: the
// outputs are well formed and the error columns mean what they say (the exact
// reference against itself has no error; the certified modes lose nothing).
// Behaviour only, never timing.
#include <catch2/catch.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "apps/bench_report.h"
#include "apps/bench_runner.h"
#include "bsprt/error.h"

using namespace bsprt;

namespace {

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  std::istringstream in(s);
  while (std::getline(in, cur, sep)) out.push_back(cur);
  return out;
}

/// Balanced brackets and braces outside strings, and no trailing commas.
bool json_looks_well_formed(const std::string& j) {
  std::string stack;
  bool in_string = false;
  char last = 0;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const char c = j[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') in_string = true;
    else if (c == '{' || c == '[') stack.push_back(c);
    else if (c == '}' || c == ']') {
      if (stack.empty() || (c == '}') != (stack.back() == '{') || last == ',') return false;
      stack.pop_back();
    }
    if (c != ' ' && c != '\n') last = c;
  }
  return stack.empty() && !in_string && j.find("nan") == std::string::npos && j.find("inf") == std::string::npos;
}

const BenchResult& tiny_run() {
  static const BenchResult result = [] {
    std::vector<BenchScene> scenes;
    scenes.push_back(load_bench_scene("icosphere:2"));
    BenchOptions o;
    o.ray_sets = {"primary", "vertex", "inside"};
    o.modes = {"exact", "brute-certified", "bsp", "bsp-float", "kd", "embree"};
    o.count = 1024;
    o.error_count = 300;
    o.threads = 2;
    o.runs = 1;
    return run_bench(scenes, o);
  }();
  return result;
}

const BenchRow& row(const std::string& set, const std::string& mode) {
  for (const BenchRow& r : tiny_run().rows)
    if (r.ray_set == set && r.mode == mode) return r;
  FAIL("no row " << set << " " << mode);
  throw;
}

}  // namespace

TEST_CASE("bench: one row per ray set and mode, with error measured", "[bench]") {
  const BenchResult& r = tiny_run();
  REQUIRE(r.rows.size() == 3 * 6);
  for (const BenchRow& row : r.rows) {
    CHECK(row.triangles == 320);
    CHECK(row.error_rays == 300);
    CHECK(row.rays >= row.error_rays);
    CHECK(row.error.rays == 300);
    CHECK(row.mrays_single > 0.0);
  }
  CHECK(row("primary", "bsp").packet_width == r.packet_width);  // exact leaves run in packets too
  CHECK(row("primary", "bsp-float").packet_width == r.packet_width);
  CHECK(row("primary", "brute-certified").packet_width == 1);
  CHECK(row("primary", "bsp").memory_bytes > 0);
  CHECK(row("primary", "bsp").triangle_tests > 0.0);
  // Stage counters of the exact leaf test: rays through vertices need its rules;
  // the float modes and Embree count none.
  CHECK(row("vertex", "bsp").rule_decisions > 0.0);
  CHECK(row("vertex", "kd").rule_decisions > 0.0);
  CHECK(row("vertex", "bsp").exact_rays <= 1.0);
  CHECK(row("vertex", "bsp-float").rule_decisions == 0.0);
  CHECK(row("vertex", "embree").rule_decisions == 0.0);
}

TEST_CASE("bench: exact against itself has zero error, and certified modes lose nothing", "[bench]") {
  for (const std::string set : {"primary", "vertex", "inside"}) {
    INFO(set);
    const BenchRow& e = row(set, "exact");
    CHECK(e.error.agrees());
    CHECK(e.error.tie == 0);
    CHECK(e.error.max_t_ulps == 0.0);
    CHECK(e.median_t_ulps == 0.0);
    for (const std::string mode : {"bsp", "kd", "brute-certified"}) {
      INFO(mode);
      CHECK(row(set, mode).error.agrees());  // the default: nothing lost, extra, farther or nearer
      CHECK(row(set, mode).error.tie == 0);   // and the same tie rule: the same triangle
      CHECK(row(set, mode).error.lost == 0);
      CHECK(row(set, mode).error.farther == 0);
    }
  }
  // Every ray from inside the closed icosphere hits.
  CHECK(row("inside", "exact").hits == row("inside", "exact").rays);
}

TEST_CASE("bench: CSV has the declared columns on every line", "[bench]") {
  const std::vector<std::string> lines = split(bench_csv(tiny_run()), '\n');
  const std::vector<std::string> columns = bench_csv_columns();
  REQUIRE(lines.size() == tiny_run().rows.size() + 1);
  CHECK(split(lines[0], ',') == columns);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> cells = split(lines[i], ',');
    REQUIRE(cells.size() == columns.size());
    CHECK(cells[0] == "icosphere-2");
    CHECK(std::all_of(cells.begin(), cells.end(), [](const std::string& c) { return !c.empty(); }));
  }
}

TEST_CASE("bench: JSON and Markdown are well formed", "[bench]") {
  const std::string j = bench_json(tiny_run());
  CHECK(json_looks_well_formed(j));
  CHECK(split(j, '\n').size() >= tiny_run().rows.size());
  std::size_t objects = 0;
  for (std::size_t p = j.find("\"scene\""); p != std::string::npos; p = j.find("\"scene\"", p + 1)) ++objects;
  CHECK(objects == tiny_run().rows.size());
  CHECK_FALSE(json_looks_well_formed("{\"a\": [1, 2,]}"));
  const std::string md = bench_markdown(tiny_run());
  std::size_t tables = 0;
  for (std::size_t p = md.find("| mode |"); p != std::string::npos; p = md.find("| mode |", p + 1)) ++tables;
  CHECK(tables == 3);
}

TEST_CASE("bench: bad modes, ray sets and scenes are usage errors", "[bench]") {
  BenchOptions o;
  o.modes = {"no-such-mode"};
  CHECK_THROWS(run_bench({}, o));
  o.modes = {"kd"};
  o.ray_sets = {"sideways"};
  CHECK_THROWS(run_bench({}, o));
  o.ray_sets = {"primary"};
  o.runs = 0;  // no timing round: a usage error, not a silent single pass
  CHECK_THROWS_AS(run_bench({}, o), UsageError);
  CHECK_THROWS(load_bench_scene("icosphere:x"));
}

TEST_CASE("bench: per-ray-set summaries hold a row per scene and the ratios of the run", "[bench]") {
  const BenchResult& r = tiny_run();
  const std::string speed = bench_speed_summary(r, "primary");
  const std::vector<std::string> lines = split(speed, '\n');
  REQUIRE(lines.size() == 3);  // header, rule, one scene
  CHECK(lines[0].find("**bsp / kd**") != std::string::npos);
  CHECK(lines[2].rfind("| icosphere-2 | 320 |", 0) == 0);
  // The bsp / kd cell is the ratio of the two rows' single-ray speeds.
  const double ratio = row("primary", "bsp").mrays_single / row("primary", "kd").mrays_single;
  CHECK(lines[2].find(fmt::format(" {:.2f} |", ratio)) != std::string::npos);
  CHECK(bench_speed_summary(r, "no-such-set").empty());
  const std::vector<std::string> err = split(bench_error_summary(r, "vertex"), '\n');
  REQUIRE(err.size() == 2 + 6);  // header, rule, a row per mode
  CHECK(err[2].find("| icosphere-2 |") == 0);
  CHECK(bench_error_summary(r, "no-such-set").empty());
}

// Issue #23: the scene whose triangles are all listed twice, the copy with
// reversed winding. Every hit ties with its copy at the same exact t; the
// certified modes must report the lower number (the original) and lose
// nothing, and the float modes' error is measured, not assumed.
TEST_CASE("bench: twin:SCENE lists every triangle twice, and the certified modes trace it exactly", "[bench]") {
  const BenchScene plain = load_bench_scene("icosphere:2");
  const BenchScene twins = load_bench_scene("twin:icosphere:2");
  CHECK(twins.name == "icosphere-2-twins");
  REQUIRE(twins.soup.size() == 2 * plain.soup.size());
  REQUIRE(twins.inside_ball.has_value());
  const std::uint32_t n = std::uint32_t(plain.soup.size());
  for (std::uint32_t i = 0; i < n; ++i) {
    REQUIRE(twins.soup.triangles[i] == plain.soup.triangles[i]);
    const TriIndices& t = plain.soup.triangles[i];
    REQUIRE(twins.soup.triangles[n + i] == TriIndices{t[0], t[2], t[1]});
  }
  CHECK_THROWS(load_bench_scene("twin:"));
  BenchOptions o;
  o.ray_sets = {"vertex", "edge", "inside"};
  o.modes = {"exact", "bsp", "kd", "bsp-float"};
  o.count = 1024;
  o.error_count = 300;
  o.threads = 2;
  o.runs = 1;
  const BenchResult r = run_bench({twins}, o);
  int rows = 0;
  for (const BenchRow& row : r.rows) {
    if (row.mode == "bsp-float") continue;
    ++rows;
    CAPTURE(row.ray_set, row.mode);
    CHECK(row.error_rays == 300);
    CHECK(row.error.lost == 0);
    CHECK(row.error.farther == 0);
    CHECK(row.error.extra == 0);
    CHECK(row.error.nearer == 0);
    CHECK(row.error.tie == 0);  // the same triangle as the reference: the original, never its copy
    CHECK(row.error.max_t_ulps == 0);
  }
  CHECK(rows == 9);
}

TEST_CASE("bench: every mode is timed once per round, and progress ends exactly at its total", "[bench]") {
  std::vector<BenchScene> scenes;
  scenes.push_back(load_bench_scene("icosphere:1"));
  BenchOptions o;
  o.ray_sets = {"primary", "random"};
  o.modes = {"bsp", "kd", "bsp-float"};
  o.count = 256;
  o.error_count = 0;
  o.threads = 1;
  o.runs = 3;
  std::vector<std::pair<std::string, std::size_t>> calls;
  std::size_t total = 0;
  o.progress = [&](const std::string& what, std::size_t done, std::size_t of) {
    calls.emplace_back(what, done);
    total = of;
  };
  const BenchResult r = run_bench(scenes, o);
  REQUIRE(r.rows.size() == 2 * 3);
  // Steps in order, 0, 1, ..., total - 1, then "done" at the total.
  REQUIRE(calls.size() == total + 1);
  for (std::size_t i = 0; i < total; ++i) CHECK(calls[i].second == i);
  CHECK(calls.back().first == "done");
  CHECK(calls.back().second == total);
  // Rounds: each round times every mode once, in the order of the modes.
  std::vector<std::string> timing;
  for (const auto& [what, done] : calls)
    if (what.find("timing round") != std::string::npos) timing.push_back(what);
  REQUIRE(timing.size() == 2 * 3 * 3);
  for (std::size_t set = 0; set < 2; ++set)
    for (std::size_t round = 0; round < 3; ++round)
      for (std::size_t m = 0; m < 3; ++m) {
        const std::string& s = timing[(set * 3 + round) * 3 + m];
        CHECK(s.find(", " + o.modes[m] + ": timing round " + std::to_string(round + 1) + " of 3") !=
              std::string::npos);
      }
  // The hits counted in the first round are the modes' own: the exact modes
  // agree with each other on every ray set.
  for (const std::string set : {"primary", "random"}) {
    std::size_t bsp = 0, kd = 0;
    for (const BenchRow& row : r.rows) {
      if (row.ray_set != set) continue;
      CHECK(row.mrays_single > 0.0);
      if (r.packet_width > 1) CHECK(row.mrays_packet > 0.0);  // bsp, kd and bsp-float all trace packets
      if (row.mode == "bsp") bsp = row.hits;
      if (row.mode == "kd") kd = row.hits;
    }
    CHECK(bsp > 0);
    CHECK(bsp == kd);
  }
}
