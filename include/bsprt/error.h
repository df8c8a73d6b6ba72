#pragma once
/// \file error.h
/// Typed errors for bad input. Library code never exits or prints: it throws one
/// of these with the file, the line or element, and what was expected; the CLI
/// turns it into a message and a non-zero exit.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

namespace bsprt {

/// Malformed or unusable input file (mesh, rays, hits, tree). `what()` reads
/// "FILE:LINE: message" (or "FILE: message" when no line applies).
class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::int64_t line, const std::string& message)
      : std::runtime_error(format(file, line, message)), file_(std::move(file)), line_(line) {}
  InputError(std::string file, const std::string& message) : InputError(std::move(file), -1, message) {}

  /// The offending file.
  const std::string& file() const { return file_; }
  /// 1-based line (text formats) or -1 when no line applies.
  std::int64_t line() const { return line_; }

 private:
  static std::string format(const std::string& file, std::int64_t line, const std::string& msg) {
    return line >= 0 ? file + ":" + std::to_string(line) + ": " + msg : file + ": " + msg;
  }
  std::string file_;
  std::int64_t line_;
};

/// A violated precondition on arguments passed by a caller (not a file).
class UsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The largest worker-thread count any `threads` option or argument takes.
/// oneTBB's arenas crash above 65535 (a segfault, not an error), and 4096 is
/// more than any machine this runs on has cores.
inline constexpr int kMaxThreads = 4096;

/// Throws UsageError naming `what` unless 0 <= threads <= kMaxThreads
/// (0 = all cores).
inline void check_threads(int threads, const std::string& what) {
  if (threads < 0 || threads > kMaxThreads)
    throw UsageError(what + " must be between 0 (all cores) and " + std::to_string(kMaxThreads) + ", not " +
                     std::to_string(threads));
}

}  // namespace bsprt
