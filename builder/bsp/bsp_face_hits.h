#pragma once
/// \file bsp_face_hits.h
/// Traversal-based triangle intersection, measured (issue 5, item 4; Ize, Wald,
/// Parker, RT 2008): an inner node split by the face plane of its own triangle
/// T, whose cross-section F = cell ∩ plane lies inside T, *proves* a hit: a ray
/// that crosses the plane inside the node's cell crosses F, so it hits T at the
/// plane's crossing parameter, which the traversal has already computed. Every
/// leaf below such a node that is bounded by F is "bounded by a triangle's own
/// plane with its face inside the triangle" in the paper's sense.
///
/// This file measures how often that applies to the nearest hits of a ray set;
/// docs/certified-epsilons.md §8 explains why the float traversal does not use
/// it (the certified intervals are outer bounds: a visit does not prove that the
/// exact ray crossed F) and what it could save. The static part (which nodes
/// prove a hit) is decided exactly; locating a hit point in the tree uses its
/// double position (see FaceHitLocator::proving_node).

#include <cstdint>
#include <vector>

#include "builder/bsp/bsp_tree.h"
#include "bsprt/ray.h"
#include "geometry/core/triangle_soup.h"
#include "robust/plane.h"

namespace bsprt {

/// Figures of one tree: inner nodes split by a triangle's face plane, and those
/// whose cross-section lies inside that triangle (exact).
struct FaceProofStats {
  std::uint64_t inner_nodes = 0;
  std::uint64_t face_nodes = 0;     ///< split by the face plane of a triangle
  std::uint64_t proving_nodes = 0;  ///< ... whose cross-section lies inside it
  double seconds = 0;
};

/// Finds, for a nearest hit, the node (if any) that proves it.
class FaceHitLocator {
 public:
  static constexpr std::uint32_t kNone = BspNode::kLeaf;

  /// Decides exactly, once per face-split node, whether its cross-section lies
  /// inside the node's triangle (one exact cell split per node, like flatten).
  /// `tree` and `soup` must outlive the locator.
  FaceHitLocator(const BspTree& tree, const TriangleSoup& soup);

  const FaceProofStats& stats() const { return stats_; }
  /// Whether inner node `node` proves hits on its plane's triangle.
  bool proves(std::uint32_t node) const { return proves_[node] != 0; }

  /// The node proving `hit` (a nearest hit on triangle hit.prim), or kNone. The
  /// hit point p = corner0 + u·(corner1 − corner0) + v·(corner2 − corner0) is
  /// located by descending from the root: a node split by hit.prim's own face
  /// plane that proves hits ends the search (p lies on its cross-section, up to
  /// the rounding of u and v); any other node sends p to the side of its plane
  /// (double evaluation; p on the plane is searched on both sides).
  std::uint32_t proving_node(const Hit& hit) const;

 private:
  std::uint32_t descend(std::uint32_t node, const Vec3d& p, PlaneDef own) const;

  const BspTree& tree_;
  const TriangleSoup& soup_;
  std::vector<std::uint8_t> proves_;
  std::vector<ApproxPlane> approx_;  ///< per entry of tree.planes()
  FaceProofStats stats_;
};

}  // namespace bsprt
