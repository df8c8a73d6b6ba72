#pragma once
/// \file stack_step.h
/// The near/far step and the stack pop of front-to-back traversal, written once
/// for the kd-tree (traverse/kd/kd_traverse.cpp) and the BSP
/// (traverse/bsp/bsp_traverse.cpp), as madmann91/bvh writes its traversal once
/// as a template (pbrt's KdTreeAggregate::Intersect loop). Inlined: the
/// kernels compile to the code they had with their own copies.

#include <bit>
#include <cstdint>

namespace bsprt::detail {

/// a where mask is all ones, b where it is 0, by bits: GCC compiles a float
/// ?: to a branch, which mispredicts where the choice follows the ray
/// (direction signs of random rays, the lanes of the interleaved kernel).
[[gnu::always_inline]] inline float select_bits(std::uint32_t mask, float a, float b) {
  return std::bit_cast<float>((std::bit_cast<std::uint32_t>(a) & mask) | (std::bit_cast<std::uint32_t>(b) & ~mask));
}

/// A deferred far child and the ray interval it is entered with.
struct StackEntry {
  std::uint32_t node;
  float tmin, tmax;
};

/// Given the children's conservative crossings (the near child is entered on
/// [tmin, near_hi], the far one on [far_lo, tmax]) and whether each is
/// visited, moves to the next node: both → push far, go near; one → go there;
/// none → returns false (the caller pops). Clips [tmin, tmax] accordingly.
[[gnu::always_inline]] inline bool step_near_far(std::uint32_t near, std::uint32_t far, bool go_near, bool go_far,
                                                 float near_hi, float far_lo, std::uint32_t& node, float& tmin,
                                                 float& tmax, StackEntry* stack, int& sp) {
  if (go_far) {
    const float far_min = far_lo > tmin ? far_lo : tmin;
    if (go_near) {
      stack[sp++] = {far, far_min, tmax};
      node = near;
      tmax = near_hi < tmax ? near_hi : tmax;
    } else {
      node = far;
      tmin = far_min;
    }
    return true;
  }
  if (go_near) {
    node = near;
    tmax = near_hi < tmax ? near_hi : tmax;
    return true;
  }
  return false;
}

/// Pops the next cell that starts before `best` (the nearest hit so far, in
/// the traversal's parameter) into node and [tmin, min(tmax, best)]; false
/// when the stack is empty.
[[gnu::always_inline]] inline bool pop_before(const StackEntry* stack, int& sp, float best, std::uint32_t& node,
                                              float& tmin, float& tmax) {
  while (sp > 0) {
    const StackEntry& e = stack[--sp];
    if (e.tmin > best) continue;
    node = e.node;
    tmin = e.tmin;
    tmax = e.tmax < best ? e.tmax : best;
    return true;
  }
  return false;
}

}  // namespace bsprt::detail
