#pragma once
/// \file bench_report.h
/// Formats a BenchResult (bench_runner.h) as a Markdown report, a CSV (one row
/// per scene × ray set × mode, read by scripts/plot_*.gp) and JSON, with speed
/// ratios against kd and Embree (robust) measured in the same run.

#include <string>
#include <vector>

#include "apps/bench_runner.h"

namespace bsprt {

/// Column names of bench_csv, in order.
std::vector<std::string> bench_csv_columns();

/// One header line (bench_csv_columns) and one line per row; no quoting needed
/// (names never hold commas).
std::string bench_csv(const BenchResult& result);

/// A JSON object: {"threads", "isa", "packet_width", "notes": [...], "rows": [{...}]}.
std::string bench_json(const BenchResult& result);

/// Markdown: per scene and ray set, a table of every mode with speed, work,
/// memory, error, and ratios vs kd and vs embree (when those modes ran).
std::string bench_markdown(const BenchResult& result);

/// Markdown summary of one ray set across scenes (what docs/performance.md
/// shows): a row per scene with every mode's single-ray Mrays/s, each BSP mode
/// against kd and Embree (single rays, and packets for bsp), and triangle tests
/// per ray of kd and the BSP modes. Empty when the run has no such ray set.
std::string bench_speed_summary(const BenchResult& result, const std::string& ray_set);

/// Markdown: the error of every mode on one ray set, a row per scene and mode
/// (rays checked, lost, farther, extra, nearer, ties, t ulps, leaks+lost per
/// million, ns per ray). Empty when no row of that set was checked.
std::string bench_error_summary(const BenchResult& result, const std::string& ray_set);

/// Single-ray speed of `mode` over that of `base` on the same scene and ray
/// set (0 when either is missing).
double bench_speed_ratio(const BenchResult& result, const BenchRow& row, const std::string& base);

}  // namespace bsprt
