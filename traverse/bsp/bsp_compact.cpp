/// \file bsp_compact.cpp
/// FlatBspTree -> CompactBspTree (bsp_compact.h).
#include "traverse/bsp/bsp_compact.h"

#include <string>

#include "bsprt/error.h"

namespace bsprt {
namespace {

class Compactor {
 public:
  explicit Compactor(const FlatBspTree& flat) : f_(flat), refs_(flat.nodes.size(), 0) {}

  CompactBspTree run() {
    count(0);
    if (refs_[0] == 0) {
      out_.slots.push_back(CompactBspSlot{});  // a root leaf without triangles
      return std::move(out_);
    }
    emit(0);
    return std::move(out_);
  }

 private:
  /// Triangle references listed under flat node i (depth <= kBspMaxDepth, checked by the caller).
  std::uint64_t count(std::uint32_t i) {
    const FlatBspNode& n = f_.nodes[i];
    refs_[i] = n.is_leaf() ? n.prim_count() : count(i + n.slots()) + count(n.second_child());
    return refs_[i];
  }

  static std::uint32_t checked(std::uint64_t v, const char* what) {
    if (v > CompactBspSlot::kMaxIndex)
      throw UsageError(std::string("BSP tree too large for the traversal layout: ") + what + " " +
                       std::to_string(v) + " exceeds " + std::to_string(CompactBspSlot::kMaxIndex));
    return std::uint32_t(v);
  }

  /// Appends flat node i (refs_[i] > 0) and its non-empty descendants.
  void emit(std::uint32_t i) {
    const FlatBspNode& n = f_.nodes[i];
    const std::size_t at = out_.slots.size();
    if (n.is_leaf()) {
      const std::uint32_t cnt = checked(n.prim_count(), "leaf size");
      out_.slots.push_back({std::uint32_t(FlatBspNodeKind::Leaf) | (cnt << CompactBspSlot::kShift), n.prim_offset()});
      return;
    }
    const std::uint32_t kind = n.bits & 7u;
    if (n.is_plane()) {
      const FlatBspNode& tail = f_.nodes[i + 1];
      out_.slots.push_back({kind, n.w[0]});
      out_.slots.push_back({n.w[1], n.w[2]});
      out_.slots.push_back({tail.bits, tail.w[0]});  // d, eps: bit for bit
    } else {
      out_.slots.push_back({kind, n.w[0]});  // split
    }
    const std::uint32_t first = i + n.slots(), second = n.second_child();
    const bool first_empty = refs_[first] == 0, second_empty = refs_[second] == 0;
    if (!first_empty) emit(first);
    std::uint32_t second_at = 0;
    if (!second_empty) {
      second_at = checked(out_.slots.size(), "slot index");
      emit(second);
    }
    out_.slots[at].head = kind | (first_empty ? CompactBspSlot::kFirstEmpty : 0u) |
                          (second_empty ? CompactBspSlot::kSecondEmpty : 0u) |
                          (second_at << CompactBspSlot::kShift);
  }

  const FlatBspTree& f_;
  std::vector<std::uint64_t> refs_;
  CompactBspTree out_;
};

}  // namespace

CompactBspTree compact_bsp(const FlatBspTree& flat) {
  if (flat.nodes.empty()) return CompactBspTree{{CompactBspSlot{}}};
  return Compactor(flat).run();
}

}  // namespace bsprt
