#pragma once
/// \file fp_env.h
/// The floating-point environment bsprt computes in, on the calling thread
/// and in every oneTBB task it runs.
///
/// Every bound bsprt relies on (the certified epsilons, the interval filters of
/// the exact predicates, the exact build and verify) assumes IEEE 754
/// arithmetic as C++ starts it: round to nearest, subnormals kept, exceptions
/// masked. Two things change that behind a library's back:
/// - the calling thread may have set flush-to-zero (FTZ) and
///   denormals-are-zero (DAZ) in MXCSR, as Embree advises its users to do;
/// - oneTBB hands a thread's floating-point settings to tasks. A task arena's
///   default context captures them when the arena is made, and every
///   algorithm run without a context of its own inherits them. Embree 3.13's
///   rtcCommitScene sets FTZ and DAZ while it runs TBB tasks, so when it is a
///   thread's first use of TBB, every later parallel loop of that thread runs
///   with FTZ and DAZ, even though the thread's own MXCSR is restored.
///   (Found 2026-12-07: verify refused a valid subnormal BSP tree after an
///   Embree tracer had been made; tests/test_fp_env.cpp.)
/// IeeeScope sets the environment on the calling thread; IeeeTasks also makes
/// a task_group_context that carries it into tasks; run_ieee runs a
/// computation in an arena made under the scope, so that every task in it,
/// nested or not, computes in IEEE arithmetic.

#include <oneapi/tbb/task_arena.h>
#include <oneapi/tbb/task_group.h>

#include <cfenv>
#include <utility>

#if defined(__x86_64__) || defined(_M_X64) || defined(__i386__)
#include <xmmintrin.h>
#define BSPRT_HAS_MXCSR 1
#else
#define BSPRT_HAS_MXCSR 0
#endif

namespace bsprt {

/// Sets IEEE 754 default arithmetic on the calling thread for its lifetime:
/// round to nearest, no FTZ, no DAZ, all exceptions masked (MXCSR 0x1F80 on
/// x86-64; elsewhere, round to nearest). Restores the caller's control bits
/// on destruction and keeps the exception flags raised in between. Costs one
/// read of MXCSR when the environment is already right.
class IeeeScope {
 public:
  IeeeScope() noexcept {
#if BSPRT_HAS_MXCSR
    saved_ = _mm_getcsr();
    if ((saved_ & kControl) != kDefault) {
      _mm_setcsr((saved_ & kFlags) | kDefault);
      changed_ = true;
    }
#else
    saved_ = unsigned(std::fegetround());
    if (saved_ != unsigned(FE_TONEAREST)) {
      std::fesetround(FE_TONEAREST);
      changed_ = true;
    }
#endif
  }
  ~IeeeScope() {
    if (!changed_) return;
#if BSPRT_HAS_MXCSR
    _mm_setcsr((saved_ & kControl) | (_mm_getcsr() & kFlags));
#else
    std::fesetround(int(saved_));
#endif
  }
  IeeeScope(const IeeeScope&) = delete;
  IeeeScope& operator=(const IeeeScope&) = delete;

  /// Whether the calling thread computes in IEEE default arithmetic now.
  static bool active() noexcept {
#if BSPRT_HAS_MXCSR
    return (_mm_getcsr() & kControl) == kDefault;
#else
    return std::fegetround() == FE_TONEAREST;
#endif
  }

#if BSPRT_HAS_MXCSR
  static constexpr unsigned kFtz = 1u << 15;   ///< MXCSR flush to zero
  static constexpr unsigned kDaz = 1u << 6;    ///< MXCSR denormals are zero
  static constexpr unsigned kControl = 0xFFC0; ///< masks, rounding, FTZ, DAZ
  static constexpr unsigned kFlags = 0x003F;   ///< sticky exception flags
  static constexpr unsigned kDefault = 0x1F80; ///< all masked, nearest, no FTZ/DAZ
#endif

 private:
  unsigned saved_ = 0;
  bool changed_ = false;
};

/// IEEE arithmetic on the calling thread, and a task_group_context that hands
/// it to every task of an algorithm run with it (and to the algorithms those
/// tasks run without a context of their own). Pass context() to the
/// outermost parallel_for / task_group of a computation.
class IeeeTasks {
 public:
  IeeeTasks()
      : context_(tbb::task_group_context::bound,
                 tbb::task_group_context::default_traits | tbb::task_group_context::fp_settings) {}
  tbb::task_group_context& context() noexcept { return context_; }

 private:
  IeeeScope scope_;                  // first: the context captures the environment it sets
  tbb::task_group_context context_;  // captures this thread's settings when made
};

/// Runs f() in IEEE arithmetic on this thread and in every task it spawns:
/// in a task arena of `threads` threads (0 = as many as the current arena's)
/// made under an IeeeScope, so that its default context, which every
/// algorithm without a context of its own inherits, holds IEEE settings. For
/// builds and checks (making an arena costs microseconds); per-batch loops
/// use IeeeTasks.
template <typename F>
decltype(auto) run_ieee(int threads, F&& f) {
  IeeeScope scope;
  tbb::task_arena arena(threads > 0 ? threads : tbb::this_task_arena::max_concurrency());
  return arena.execute(std::forward<F>(f));
}

}  // namespace bsprt
