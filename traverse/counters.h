#pragma once
/// \file counters.h
/// Per-ray work counters. They are deterministic (unlike timings), so tests and
/// benchmarks can compare structures by them. Compiled in always; a tracer only
/// touches them when handed a non-null pointer.

#include <cstdint>

namespace bsprt {

/// Work done while tracing; add them up over many rays and divide.
struct RayCounters {
  std::uint64_t rays = 0;             ///< rays traced
  std::uint64_t kd_node_visits = 0;   ///< inner nodes with an axis-aligned plane
  std::uint64_t bsp_node_visits = 0;  ///< inner nodes with a general plane
  std::uint64_t leaf_visits = 0;      ///< leaves entered
  std::uint64_t triangle_tests = 0;   ///< ray/triangle tests run
  std::uint64_t box_node_visits = 0;  ///< 4-wide box nodes of a box top (bsp_boxtop.h)

  RayCounters& operator+=(const RayCounters& o) {
    rays += o.rays;
    kd_node_visits += o.kd_node_visits;
    bsp_node_visits += o.bsp_node_visits;
    leaf_visits += o.leaf_visits;
    triangle_tests += o.triangle_tests;
    box_node_visits += o.box_node_visits;
    return *this;
  }
};

}  // namespace bsprt
