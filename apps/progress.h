#pragma once
/// \file progress.h
/// A terminal progress bar for long work (builds, renders, traces): done/total,
/// rate and time left, redrawn at most ten times a second on stderr, and
/// silent when stderr is not a terminal (CI logs, pipes).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace bsprt {

/// Thread-safe progress bar; call `advance` or `set` from any thread.
class ProgressBar {
 public:
  /// `unit` names what is counted ("rays", "triangles", "tiles").
  ProgressBar(std::string label, std::uint64_t total, std::string unit, bool enabled);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  /// Adds `n` units done.
  void advance(std::uint64_t n);
  /// Sets the units done (for callbacks that report totals).
  void set(std::uint64_t done);
  /// Draws the final state and ends the line (idempotent).
  void finish();

  /// True when stderr is a terminal and the environment does not ask for quiet (CI).
  static bool stderr_is_terminal();

 private:
  void draw(bool final);
  std::string label_, unit_;
  std::uint64_t total_;
  bool enabled_;
  bool finished_ = false;
  std::atomic<std::uint64_t> done_{0};
  std::atomic<std::int64_t> last_draw_ns_{0};
  std::mutex draw_mutex_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace bsprt
