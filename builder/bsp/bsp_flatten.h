#pragma once
/// \file bsp_flatten.h
/// THE one bridge from the exact BSP tree (bsp_tree.h, planes by defining data,
/// exact cells) to the flat float tree traversal reads (traverse/bsp_node.h):
/// STYLE.md 1, like pbrt-v4's flattenBVH. Per node:
///   - kd plane → kd node (its coordinate is a float: exact, no epsilon);
///   - face/edge plane whose exact normal is axis-aligned → kd node too (the
///     offset is a float corner coordinate), children swapped if it points down;
///   - other face/edge plane → plane node: the normalized plane rounded to
///     float, and eps certified from the exact cell's vertices
///     (robust/epsilon_bound.h, docs/certified-epsilons.md).
/// Children are laid out depth-first, first child adjacent (Ize, Wald,
/// Parker, RT 2008, §5).

#include <cstddef>
#include <cstdint>
#include <memory>

#include "builder/bsp/bsp_tree.h"
#include "geometry/core/triangle_soup.h"
#include "robust/epsilon_bound.h"
#include "traverse/bsp/bsp_node.h"
#include "traverse/bsp/bsp_traverse.h"
#include "traverse/accelerator.h"

namespace bsprt {

/// What flatten_bsp did.
struct FlattenReport {
  std::size_t plane_nodes = 0;      ///< general planes (dot-product nodes)
  std::size_t kd_nodes = 0;         ///< axis-aligned nodes, including...
  std::size_t kd_from_planes = 0;   ///< ...face/edge planes that were exactly axis-aligned
  std::size_t leaves = 0;           ///< leaves
  double scene_scale = 0.0;         ///< max |coordinate| of the root box
  double max_eps = 0.0;             ///< largest stored eps
  double mean_eps = 0.0;            ///< mean stored eps over plane nodes
  double max_eps_rel_cell = 0.0;    ///< max over plane nodes of eps / cell diameter
  double seconds = 0.0;             ///< wall time
  ExactStats exact;                 ///< exact work of the cell recomputation
};

/// Flattens `exact` (built for `soup`) into the float tree. Recomputes every
/// cell once (BspTree::for_each_cell) to certify the plane epsilons. Throws
/// UsageError when the tree does not validate for `soup`, is deeper than
/// kBspMaxDepth, or a plane's bound is not finite.
FlatBspTree flatten_bsp(const TriangleSoup& soup, const BspTree& exact,
                        FlattenReport* report = nullptr);

/// The float plane and certified epsilon flatten_bsp stores for a face/edge
/// `plane` splitting `cell` (exposed so tests can check the bound against
/// exact evaluation at points of the cell).
FloatPlane flat_plane_of(const TriangleSoup& soup, PlaneDef plane, const Cell& cell);

}  // namespace bsprt
