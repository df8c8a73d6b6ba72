#pragma once
/// \file bsp_build.h
/// The exact general BSP build (Ize, Wald, Parker, "Ray Tracing with the BSP
/// Tree", RT 2008): top-down SAH over kd candidates (sorted-event sweeps) and,
/// where the node is small enough to profit, face/edge candidates counted with a
/// bounding-sphere hierarchy; cells are exact convex polytopes, triangles are
/// clipped to cells exactly ("perfect splits"), every membership decision is
/// exact (robust/). Subtrees are built in parallel with oneTBB. See
/// docs/bsp-build.md.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "builder/bsp/bsp_config.h"
#include "builder/bsp/bsp_tree.h"
#include "geometry/core/triangle_soup.h"
#include "robust/exact_side.h"

namespace bsprt {

/// What one build did (for `bsprt stats`, benchmarks and docs).
struct BspBuildReport {
  double seconds = 0;                  ///< wall time of build_bsp
  std::size_t triangles = 0;           ///< triangles in the scene
  std::size_t degenerate = 0;          ///< triangles left out (degenerate: never hit)
  std::size_t nodes = 0;               ///< all nodes
  std::size_t leaves = 0;              ///< leaf nodes
  std::size_t empty_leaves = 0;        ///< leaves without triangles
  std::size_t triangle_refs = 0;       ///< sum of leaf sizes
  std::size_t kd_splits = 0;           ///< inner nodes split by an axis-aligned plane
  std::size_t bsp_splits = 0;          ///< inner nodes split by a face or edge plane
  std::size_t max_depth = 0;           ///< deepest leaf
  std::size_t depth_limited = 0;       ///< leaves forced by BspConfig::max_depth
  std::vector<std::size_t> kd_by_depth;   ///< kd splits per depth
  std::vector<std::size_t> bsp_by_depth;  ///< face/edge splits per depth
  std::vector<std::size_t> leaf_histogram;  ///< leaf_histogram[n] = leaves holding n triangles
  std::size_t failed_split_attempts = 0;  ///< best candidates rejected by the exact split
  double sah_cost = 0;                 ///< SAH cost of the tree (root area normalized)
  ExactStats exact;                    ///< filter calls, exact fallbacks, symbolic zeros
};

/// Progress: `done` of `total` triangle-weight finished in leaves (done reaches
/// total at the end). Called from worker threads, serialized by the builder, at
/// most about once per 0.1 %. The library never prints: the CLI draws the bar.
using BspProgressFn = std::function<void(double done, double total)>;

/// Builds the exact BSP tree over the non-degenerate triangles of `soup`
/// (degenerate ones — soup.is_degenerate or exactly collinear corners — can never
/// be hit and are left out). The result satisfies tree.validate(soup.size()).
BspTree build_bsp(const TriangleSoup& soup, const BspConfig& config = {},
                  BspBuildReport* report = nullptr, const BspProgressFn& progress = {});

/// The root cell build_bsp uses: the bounds of the non-degenerate triangles,
/// widened (by a float step relative to the scene size) along flat axes.
Box3f bsp_root_box(const TriangleSoup& soup, const std::vector<std::uint32_t>& triangles);

}  // namespace bsprt
