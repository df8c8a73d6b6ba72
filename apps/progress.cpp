#include "apps/progress.h"

#include <fmt/core.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

namespace bsprt {

ProgressBar::ProgressBar(std::string label, std::uint64_t total, std::string unit, bool enabled)
    : label_(std::move(label)), unit_(std::move(unit)), total_(total), enabled_(enabled),
      start_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() { finish(); }

bool ProgressBar::stderr_is_terminal() { return isatty(STDERR_FILENO) != 0 && std::getenv("CI") == nullptr; }

void ProgressBar::advance(std::uint64_t n) {
  done_.fetch_add(n, std::memory_order_relaxed);
  draw(false);
}

void ProgressBar::set(std::uint64_t done) {
  done_.store(done, std::memory_order_relaxed);
  draw(false);
}

void ProgressBar::finish() {
  if (finished_) return;
  draw(true);
  finished_ = true;
  if (enabled_) std::fputc('\n', stderr);
}

void ProgressBar::draw(bool final) {
  if (!enabled_ || finished_) return;
  const auto now = std::chrono::steady_clock::now();
  const std::int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now - start_).count();
  std::int64_t last = last_draw_ns_.load(std::memory_order_relaxed);
  if (!final && ns - last < 100'000'000) return;
  if (!last_draw_ns_.compare_exchange_strong(last, ns) && !final) return;
  std::lock_guard lock(draw_mutex_);
  const std::uint64_t done = std::min(done_.load(), total_);
  const double frac = total_ ? double(done) / double(total_) : 1.0;
  const double secs = double(ns) * 1e-9;
  const double left = frac > 0 ? secs * (1.0 - frac) / frac : 0.0;
  constexpr int kWidth = 30;
  const int filled = int(frac * kWidth);
  std::string bar(std::size_t(filled), '#');
  bar.resize(kWidth, '.');
  fmt::print(stderr, "\r{} [{}] {:5.1f}% {}/{} {} {:.1f}s elapsed, {:.1f}s left   ", label_, bar,
             frac * 100.0, done, total_, unit_, secs, left);
  std::fflush(stderr);
}

}  // namespace bsprt
