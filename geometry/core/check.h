#pragma once
/// \file check.h
/// Checks in two strengths (pbrt-v4's CHECK/DCHECK): BSPRT_CHECK is always on and
/// throws std::logic_error naming both operands; BSPRT_DCHECK compiles away in
/// release builds and guards internal invariants on hot paths.

#include <sstream>
#include <stdexcept>

namespace bsprt::detail {
template <typename A, typename B>
[[noreturn]] void check_failed(const char* expr, const A& a, const B& b, const char* file, int line) {
  std::ostringstream s;
  s << file << ":" << line << ": check failed: " << expr << " (" << a << " vs " << b << ")";
  throw std::logic_error(s.str());
}
[[noreturn]] inline void check_failed(const char* expr, const char* file, int line) {
  std::ostringstream s;
  s << file << ":" << line << ": check failed: " << expr;
  throw std::logic_error(s.str());
}
}  // namespace bsprt::detail

#define BSPRT_CHECK(c) \
  do { if (!(c)) ::bsprt::detail::check_failed(#c, __FILE__, __LINE__); } while (0)
#define BSPRT_CHECK_OP(a, op, b)                                                          \
  do {                                                                                    \
    const auto& bsprt_a_ = (a);                                                           \
    const auto& bsprt_b_ = (b);                                                           \
    if (!(bsprt_a_ op bsprt_b_))                                                          \
      ::bsprt::detail::check_failed(#a " " #op " " #b, bsprt_a_, bsprt_b_, __FILE__, __LINE__); \
  } while (0)
#define BSPRT_CHECK_EQ(a, b) BSPRT_CHECK_OP(a, ==, b)
#define BSPRT_CHECK_LE(a, b) BSPRT_CHECK_OP(a, <=, b)
#define BSPRT_CHECK_LT(a, b) BSPRT_CHECK_OP(a, <, b)

#ifdef NDEBUG
#define BSPRT_DCHECK(c) do { } while (0)
#else
#define BSPRT_DCHECK(c) BSPRT_CHECK(c)
#endif
