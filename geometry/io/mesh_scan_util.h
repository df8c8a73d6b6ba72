#pragma once
/// \file mesh_scan_util.h
/// Internal helpers of the mesh pre-passes: lines, tokens, integers.

#include <cstdint>
#include <string>
#include <string_view>

namespace bsprt::detail {

/// Walks the lines of a buffer; a line excludes its '\n' and a trailing '\r'.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text, std::size_t start = 0, std::int64_t first_line = 1)
      : text_(text), pos_(start), next_number_(first_line) {}
  /// Next line into `line`; false at the end of the buffer.
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string_view::npos) end = text_.size();
    std::size_t stop = end;
    if (stop > pos_ && text_[stop - 1] == '\r') --stop;
    line = text_.substr(pos_, stop - pos_);
    pos_ = end == text_.size() ? end : end + 1;  // a last line without '\n' ends at the buffer's end
    number_ = next_number_++;
    return true;
  }
  /// 1-based number of the line last returned.
  std::int64_t number() const { return number_; }
  /// Offset just past the line last returned (and its '\n'); never past the end.
  std::size_t offset() const { return pos_; }

 private:
  std::string_view text_;
  std::size_t pos_;
  std::int64_t next_number_;
  std::int64_t number_ = 0;
};

inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' || c == '\n'; }

/// The next whitespace-separated token of `s` from position `i` (advanced
/// past it); empty at the end.
inline std::string_view next_token(std::string_view s, std::size_t& i) {
  while (i < s.size() && is_blank(s[i])) ++i;
  const std::size_t b = i;
  while (i < s.size() && !is_blank(s[i])) ++i;
  return s.substr(b, i - b);
}

/// Parses a whole token as a (possibly signed) decimal integer.
bool parse_index(std::string_view token, std::int64_t& value);

/// Overwrites `token` (a view into `bytes`) with `first` then blanks, keeping
/// its length so that offsets and line numbers do not move.
void blank_out(std::string& bytes, std::string_view token, char first);

/// "0..n-1" for messages about indices, or "(there are no vertices)".
inline std::string valid_range(std::size_t n) {
  return n == 0 ? std::string("(there are no vertices)") : "0.." + std::to_string(n - 1);
}

/// `token` in quotes, shortened for messages.
std::string quote(std::string_view token);

}  // namespace bsprt::detail
