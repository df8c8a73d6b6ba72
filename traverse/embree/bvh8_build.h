#pragma once
/// \file bvh8_build.h
/// Building the plain BVH8 of traverse/bvh/bvh8_node.h with Embree's SAH
/// builder (rtcBuildBVH): Embree chooses the splits, our callbacks record
/// them, and the boxes are then recomputed from the triangles' float corners
/// (exact min/max), so the tree's certificate does not rest on Embree.

#include <cstdint>

#include "geometry/core/triangle_soup.h"
#include "traverse/bsp/bsp_traverse.h"
#include "traverse/bvh/bvh8_node.h"

namespace bsprt {

/// Build settings; the defaults are Embree 3.13's own for its BVH8 of
/// four-triangle blocks (kernels/bvh/bvh_builder_sah.cpp: block size 4,
/// intersection cost 1, minimum leaf size 4), with leaves of one block.
struct Bvh8Config {
  unsigned max_leaf_size = 4;    ///< triangles per leaf at most (1..4: one four-lane block)
  /// Nodes of at most this many triangles become leaves unsplit (1..max_leaf_size):
  /// four triangles are one four-lane test, and splitting them only adds box
  /// tests (sponza random rays: 1,405 -> 1,195 instructions a ray).
  unsigned min_leaf_size = 4;
  unsigned sah_block_size = 4;   ///< a leaf costs intersection_cost per started block of this many
  float traversal_cost = 1.0f;   ///< SAH cost of a node step
  float intersection_cost = 1.0f;  ///< SAH cost of a block test
};

/// Builds the BVH8 over the triangles of `soup`; degenerate triangles and
/// triangles with non-finite corners are left out (counted in left_out: no
/// mode hits them). Throws UsageError for a bad config, std::runtime_error
/// when Embree fails.
Bvh8Tree build_bvh8(const TriangleSoup& soup, const Bvh8Config& config = {});

/// A BVH8 top over `bsp` (issue #26 step two; Bvh8Tree::over_bsp): the tree
/// cut into pieces (BspTracer::subtree_boxes), each a leaf of the BVH8 under
/// its certified box. A subtree whose leaves list at most `leaf_triangles`
/// distinct triangles becomes a triangle leaf of those (tested at once, four
/// lanes); the rest are cut into subtrees of at most `max_slots` slots and
/// stay BSP subtrees. leaf_triangles 0: only the size rule (every piece a
/// subtree). Throws UsageError for max_slots 0 or leaf_triangles > 4,
/// std::runtime_error when Embree fails.
Bvh8Tree build_bvh8_over_bsp(const BspTracer& bsp, std::uint32_t max_slots, std::uint32_t leaf_triangles = 4);

/// tracer.set_bvh8_top(build_bvh8_over_bsp(tracer, max_slots)).
void add_bvh8_top(BspTracer& tracer, std::uint32_t max_slots);

}  // namespace bsprt
