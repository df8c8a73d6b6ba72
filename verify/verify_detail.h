#pragma once
/// \file verify_detail.h
/// Shared state of the verifier's passes (verify_structure.cpp: ids, reach,
/// header checks; verify_tree.cpp: the exact walk). Internal to robust/.

#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <vector>

#include "verify/verify.h"
#include "verify/verify_geometry.h"

namespace bsprt::vfy {

/// Results of the structural pass that the exact walk needs.
struct Structure {
  std::vector<std::uint8_t> degenerate;  ///< per triangle, exact
  std::vector<std::uint32_t> pre;        ///< preorder number per node
  std::vector<std::uint32_t> end;        ///< one past the last preorder number of the subtree
  /// Per triangle, sorted preorder numbers of the leaves listing it (CSR).
  std::vector<std::uint32_t> tri_leaf_start, tri_leaf_pre;
  std::uint64_t leaves = 0;
};

/// First failure (lowest node id) across threads, and the stop flag.
class FailureSink {
 public:
  void fail(VerifyFailure f) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!best_ || f.node < best_->node) best_ = std::move(f);
    stop_.store(true, std::memory_order_relaxed);
  }
  bool stopped() const { return stop_.load(std::memory_order_relaxed); }
  const std::optional<VerifyFailure>& best() const { return best_; }

 private:
  std::mutex mutex_;
  std::optional<VerifyFailure> best_;
  std::atomic<bool> stop_{false};
};

/// Checks (d): header, planes, node ids, reach-once, leaf lists, triangles in
/// the root box, the flat header. Fills `st`; reports the first failure to
/// `sink` and returns false on failure.
bool check_structure(const TriangleSoup& soup, const VerifyInput& in, Structure& st, FailureSink& sink);

/// True when triangle `tri` is listed by a leaf of the subtree of `node`.
bool listed_in_subtree(const Structure& st, std::uint32_t tri, std::uint32_t node);

}  // namespace bsprt::vfy
