/// \file bench_report.cpp
/// Markdown, CSV and JSON views of a BenchResult.
#include "apps/bench_report.h"

#include <fmt/core.h>

#include <algorithm>

#include "builder/accel_factory.h"

namespace bsprt {
namespace {

/// Leaks and lost hits per million rays: (lost + farther) / rays · 1e6.
double leaks_per_million(const BenchRow& r) {
  return r.error_rays ? double(r.error.lost + r.error.farther) / double(r.error_rays) * 1e6 : 0.0;
}

/// Wall nanoseconds per ray, single rays, all threads.
double ns_per_ray(const BenchRow& r) { return r.mrays_single > 0 ? 1e3 / r.mrays_single : 0.0; }

std::string ratio_cell(double x) { return x > 0 ? fmt::format("{:.2f}", x) : std::string("–"); }

std::string md_table_header() {
  return "| mode | build s | Mrays/s single | Mrays/s packet | vs kd | vs embree | kd+bsp nodes/ray | box nodes/ray "
         "| tri tests/ray | rule / Mpzf decisions per ray | rays to Mpzf | MB | bytes/tri | error rays | lost | extra "
         "| farther (leaks) | nearer | max t ulps | median t ulps |\n"
         "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
}

std::string md_row(const BenchResult& res, const BenchRow& r) {
  const bool err = r.error_rays > 0;
  const auto cnt = [&](std::uint64_t v) { return err ? fmt::format("{}", v) : std::string("–"); };
  const bool counted = r.kd_visits + r.bsp_visits + r.box_visits + r.triangle_tests > 0;  // Embree has no counters
  const bool exact = bench_mode_is_certified(r.mode) && counted;  // the staged exact leaf test counts its stages
  return fmt::format("| {} | {:.3f} | {:.2f} | {} | {} | {} | {} | {} | {} | {} | {} | {:.1f} | {} | {} | {} | {} | {} | {} "
                     "| {} | {} |\n",
                     r.mode, r.build_seconds, r.mrays_single,
                     r.packet_width > 1 ? fmt::format("{:.2f} ({})", r.mrays_packet, r.packet_width) : "single only",
                     ratio_cell(bench_speed_ratio(res, r, "kd")), ratio_cell(bench_speed_ratio(res, r, "embree")),
                     counted ? fmt::format("{:.1f}", r.kd_visits + r.bsp_visits) : "–",
                     counted ? fmt::format("{:.1f}", r.box_visits) : "–",
                     counted ? fmt::format("{:.2f}", r.triangle_tests) : "–",
                     exact ? fmt::format("{:.3f} / {:.4f}", r.rule_decisions, r.exact_decisions) : "–",
                     exact ? fmt::format("{:.3f}%", 100.0 * r.exact_rays) : "–", double(r.memory_bytes) / 1e6,
                     r.triangles && r.memory_bytes ? fmt::format("{:.0f}", double(r.memory_bytes) / double(r.triangles))
                                                   : std::string("–"),
                     err ? fmt::format("{}", r.error_rays) : "–", cnt(r.error.lost), cnt(r.error.extra),
                     cnt(r.error.farther), cnt(r.error.nearer), err ? fmt::format("{:.0f}", r.error.max_t_ulps) : "–",
                     err ? fmt::format("{:.1f}", r.median_t_ulps) : "–");
}

/// Rows grouped by (scene, ray set) in first-seen order.
std::vector<std::vector<const BenchRow*>> groups(const BenchResult& res) {
  std::vector<std::vector<const BenchRow*>> out;
  for (const BenchRow& r : res.rows) {
    if (out.empty() || out.back().front()->scene != r.scene || out.back().front()->ray_set != r.ray_set)
      out.emplace_back();
    out.back().push_back(&r);
  }
  return out;
}

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) >= 0x20) out += c;
  }
  return out + "\"";
}

std::string json_row(const BenchResult& res, const BenchRow& r) {
  return fmt::format(
      "{{\"scene\": {}, \"triangles\": {}, \"rays\": {}, \"mode\": {}, \"ray_count\": {}, \"build_seconds\": {:.6f}, "
      "\"mrays_single\": {:.4f}, \"mrays_packet\": {:.4f}, \"packet_width\": {}, \"kd_visits\": {:.4f}, "
      "\"bsp_visits\": {:.4f}, \"leaf_visits\": {:.4f}, \"triangle_tests\": {:.4f}, \"memory_bytes\": {}, "
      "\"hits\": {}, \"error_rays\": {}, \"lost\": {}, \"extra\": {}, \"farther\": {}, \"nearer\": {}, \"tie\": {}, "
      "\"max_t_ulps\": {:.1f}, \"median_t_ulps\": {:.1f}, \"leaks_per_million\": {:.2f}, \"speed_vs_kd\": {:.4f}, "
      "\"speed_vs_embree\": {:.4f}, \"box_visits\": {:.4f}, \"rule_decisions\": {:.6f}, \"exact_decisions\": {:.6f}, "
      "\"exact_rays\": {:.6f}}}",
      json_string(r.scene), r.triangles, json_string(r.ray_set), json_string(r.mode), r.rays, r.build_seconds,
      r.mrays_single, r.mrays_packet, r.packet_width, r.kd_visits, r.bsp_visits, r.leaf_visits, r.triangle_tests,
      r.memory_bytes, r.hits, r.error_rays, r.error.lost, r.error.extra, r.error.farther, r.error.nearer, r.error.tie,
      r.error.max_t_ulps, r.median_t_ulps, leaks_per_million(r), bench_speed_ratio(res, r, "kd"),
      bench_speed_ratio(res, r, "embree"), r.box_visits, r.rule_decisions, r.exact_decisions, r.exact_rays);
}

/// The modes of the run, in first-seen order.
std::vector<std::string> modes_of(const BenchResult& res) {
  std::vector<std::string> out;
  for (const BenchRow& r : res.rows)
    if (std::find(out.begin(), out.end(), r.mode) == out.end()) out.push_back(r.mode);
  return out;
}

const BenchRow* find_row(const std::vector<const BenchRow*>& g, const std::string& mode) {
  for (const BenchRow* r : g)
    if (r->mode == mode) return r;
  return nullptr;
}

}  // namespace

std::string bench_speed_summary(const BenchResult& res, const std::string& ray_set) {
  const std::vector<std::string> modes = modes_of(res);
  std::vector<std::string> bsp_modes, counted;  // BSP modes (ratios), modes with triangle counters
  for (const std::string& m : modes) {
    if (accel_info(m).tree == AccelTree::Bsp && accel_info(m).packets) bsp_modes.push_back(m);
    if (accel_info(m).tree != AccelTree::None && accel_info(m).packets) counted.push_back(m);
  }
  // What exactness costs: the default (exact leaves) against the float leaf test.
  const auto has = [&](const char* m) { return std::find(modes.begin(), modes.end(), m) != modes.end(); };
  const bool has_float = has("bsp-float") && has("bsp"), has_kd_float = has("kd-float") && has("kd");
  const bool has_kd = std::find(modes.begin(), modes.end(), "kd") != modes.end();
  const bool has_embree = std::find(modes.begin(), modes.end(), "embree") != modes.end();
  std::string head = "| scene | triangles |", rule = "|---|---:|";
  for (const std::string& m : modes) head += " " + m + " |", rule += "---:|";
  for (const std::string& m : bsp_modes) {
    if (has_kd) head += " **" + m + " / kd** |", rule += "---:|";
    if (has_embree) head += " **" + m + " / embree** |", rule += "---:|";
  }
  const bool packets = std::find(modes.begin(), modes.end(), "bsp") != modes.end();
  if (packets && has_kd) head += " bsp packets / kd packets |", rule += "---:|";
  if (packets && has_embree) head += " bsp packets / embree packets |", rule += "---:|";
  if (has_float) head += " bsp time / bsp-float time | packets |", rule += "---:|---:|";
  if (has_kd_float) head += " kd time / kd-float time | packets |", rule += "---:|---:|";
  std::string tests_head;
  for (const std::string& m : counted) tests_head += (tests_head.empty() ? "" : " → ") + m;
  if (!counted.empty()) head += " tri tests/ray " + tests_head + " |", rule += "---:|";
  std::string body;
  for (const auto& g : groups(res)) {
    if (g.front()->ray_set != ray_set) continue;
    body += fmt::format("| {} | {} |", g.front()->scene, g.front()->triangles);
    for (const std::string& m : modes) {
      const BenchRow* r = find_row(g, m);
      body += r ? fmt::format(" {:.2f} |", r->mrays_single) : std::string(" – |");
    }
    const auto ratio = [&](const std::string& m, const std::string& base, bool packet) {
      const BenchRow *a = find_row(g, m), *b = find_row(g, base);
      const double x = a ? (packet ? a->mrays_packet : a->mrays_single) : 0.0;
      const double y = b ? (packet ? b->mrays_packet : b->mrays_single) : 0.0;
      return " " + ratio_cell(x > 0 && y > 0 ? x / y : 0.0) + " |";
    };
    for (const std::string& m : bsp_modes) {
      if (has_kd) body += ratio(m, "kd", false);
      if (has_embree) body += ratio(m, "embree", false);
    }
    if (packets && has_kd) body += ratio("bsp", "kd", true);
    if (packets && has_embree) body += ratio("bsp", "embree", true);
    if (has_float) body += ratio("bsp-float", "bsp", false) + ratio("bsp-float", "bsp", true);
    if (has_kd_float) body += ratio("kd-float", "kd", false) + ratio("kd-float", "kd", true);
    if (!counted.empty()) {
      std::string tests;
      for (const std::string& m : counted) {
        const BenchRow* r = find_row(g, m);
        tests += (tests.empty() ? "" : " → ") + (r ? fmt::format("{:.2f}", r->triangle_tests) : std::string("–"));
      }
      body += " " + tests + " |";
    }
    body += "\n";
  }
  return body.empty() ? std::string() : head + "\n" + rule + "\n" + body;
}

std::string bench_error_summary(const BenchResult& res, const std::string& ray_set) {
  std::string body;
  for (const BenchRow& r : res.rows)
    if (r.ray_set == ray_set && r.error_rays > 0)
      body += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {:.0f} | {:.1f} | {:.1f} | {:.1f} |\n", r.scene,
                          r.mode, r.error_rays, r.error.lost, r.error.farther, r.error.extra, r.error.nearer,
                          r.error.tie, r.error.max_t_ulps, r.median_t_ulps, leaks_per_million(r), ns_per_ray(r));
  if (body.empty()) return {};
  return "| scene | mode | rays checked | lost | farther (leaks) | extra | nearer | ties | max t ulps | median t ulps "
         "| leaks+lost per M | ns/ray |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n" +
         body;
}

double bench_speed_ratio(const BenchResult& result, const BenchRow& row, const std::string& base) {
  for (const BenchRow& b : result.rows)
    if (b.scene == row.scene && b.ray_set == row.ray_set && b.mode == base && b.mrays_single > 0 && b.rays == row.rays)
      return row.mrays_single / b.mrays_single;
  return 0.0;
}

std::vector<std::string> bench_csv_columns() {
  return {"scene",        "triangles",     "rays",        "mode",           "ray_count",     "build_seconds",
          "mrays_single", "mrays_packet",  "packet_width", "kd_visits",     "bsp_visits",    "leaf_visits",
          "triangle_tests", "memory_bytes", "hits",        "error_rays",    "lost",          "extra",
          "farther",      "nearer",        "tie",         "max_t_ulps",     "median_t_ulps", "leaks_per_million",
          "ns_per_ray",   "speed_vs_kd",   "speed_vs_embree", "box_visits", "rule_decisions", "exact_decisions",
          "exact_rays"};
}

std::string bench_csv(const BenchResult& res) {
  std::string out;
  for (const std::string& c : bench_csv_columns()) out += (out.empty() ? "" : ",") + c;
  out += "\n";
  for (const BenchRow& r : res.rows)
    out += fmt::format("{},{},{},{},{},{:.6f},{:.4f},{:.4f},{},{:.4f},{:.4f},{:.4f},{:.4f},{},{},{},{},{},{},{},{},{:.1f},"
                       "{:.1f},{:.2f},{:.3f},{:.4f},{:.4f},{:.4f},{:.6f},{:.6f},{:.6f}\n",
                       r.scene, r.triangles, r.ray_set, r.mode, r.rays, r.build_seconds, r.mrays_single, r.mrays_packet,
                       r.packet_width, r.kd_visits, r.bsp_visits, r.leaf_visits, r.triangle_tests, r.memory_bytes, r.hits,
                       r.error_rays, r.error.lost, r.error.extra, r.error.farther, r.error.nearer, r.error.tie,
                       r.error.max_t_ulps, r.median_t_ulps, leaks_per_million(r), ns_per_ray(r),
                       bench_speed_ratio(res, r, "kd"), bench_speed_ratio(res, r, "embree"), r.box_visits,
                       r.rule_decisions, r.exact_decisions, r.exact_rays);
  return out;
}

std::string bench_json(const BenchResult& res) {
  std::string out = fmt::format("{{\"threads\": {}, \"isa\": {}, \"packet_width\": {}, \"notes\": [", res.threads,
                                json_string(res.isa), res.packet_width);
  for (std::size_t i = 0; i < res.notes.size(); ++i) out += (i ? ", " : "") + json_string(res.notes[i]);
  out += "],\n\"rows\": [\n";
  for (std::size_t i = 0; i < res.rows.size(); ++i) out += (i ? ",\n" : "") + json_row(res, res.rows[i]);
  return out + "\n]}\n";
}

std::string bench_markdown(const BenchResult& res) {
  std::string out;
  for (const auto& g : groups(res)) {
    const BenchRow& f = *g.front();
    out += fmt::format("\n#### {} ({} triangles), {} rays: {} timed, {} checked against the exact reference\n\n",
                       f.scene, f.triangles, f.ray_set, f.rays, f.error_rays);
    out += md_table_header();
    for (const BenchRow* r : g) out += md_row(res, *r);
  }
  for (const std::string& n : res.notes) out += "\n- " + n;
  if (!res.notes.empty()) out += "\n";
  return out;
}

}  // namespace bsprt
