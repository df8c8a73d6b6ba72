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
  std::uint64_t box_node_visits = 0;  ///< box nodes: 4-wide of a box top (bsp_boxtop.h), 8-wide of the BVH8 (bvh8_node.h)
  /// Exact-decision leaf tests (robust/certified_intersector.h): decisions
  /// the double filter could not make that a rule on exact zeros made (a ray
  /// through a vertex, hits at one vertex, edge or triangle tied), decisions
  /// made in exact arithmetic (CGAL::Mpzf), and rays with at least one of those.
  std::uint64_t rule_decisions = 0;
  std::uint64_t exact_decisions = 0;
  std::uint64_t exact_rays = 0;

  RayCounters& operator+=(const RayCounters& o) {
    rays += o.rays;
    kd_node_visits += o.kd_node_visits;
    bsp_node_visits += o.bsp_node_visits;
    leaf_visits += o.leaf_visits;
    triangle_tests += o.triangle_tests;
    box_node_visits += o.box_node_visits;
    rule_decisions += o.rule_decisions;
    exact_decisions += o.exact_decisions;
    exact_rays += o.exact_rays;
    return *this;
  }
};

}  // namespace bsprt
