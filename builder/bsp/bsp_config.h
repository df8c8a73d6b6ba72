#pragma once
/// \file bsp_config.h
/// Options of the exact BSP build (build_bsp in bsp_build.h) with their
/// documented defaults, and the rule that decides which children a clipped
/// triangle belongs to.

#include <cstddef>
#include <cstdint>

#include "robust/exact_polygon.h"

namespace bsprt {

/// Which triangles a node holds (the invariant a verifier checks).
enum class BspMembership : std::uint8_t {
  /// T is in a node iff T touches the node's closed cell (T ∩ C ≠ ∅): what
  /// issue 4 and `bsprt verify` state. Neighbours that only touch a cell's
  /// boundary are listed too, so a leaf rarely holds a single triangle of a
  /// closed mesh.
  Closed = 0,
  /// T is in a node iff T ∩ C has positive area. Also correct for closed-interval
  /// traversal (a ray hitting T at x visits every leaf whose closed cell holds x,
  /// and T has positive area in one of them; docs/bsp-build.md), and gives the
  /// paper's one-triangle leaves. A verifier must check this weaker rule.
  Area = 1,
};

/// Options of build_bsp. Costs follow docs/bsp-build.md "Costs" (the reference
/// implementation of Ize, Wald, Parker 2008, §4): cost(split) = C_trav +
/// C_isect·(P_L·N_L + P_R·N_R) with P = child cell area / parent cell area.
struct BspConfig {
  double c_isect = 75.0;      ///< cost of one ray–triangle test; a leaf costs c_isect·N
  double c_kd = 10.0;         ///< traversal cost of a kd (axis-aligned) node
  double c_bsp_slope = 0.1;   ///< C_BSP = c_bsp_slope·c_isect·(N−2) + c_kd when a kd split cuts the node
  double c_bsp_fixed = 20.0;  ///< C_BSP when no kd candidate cuts the node
  /// Split cost factor when one child lists no triangle (Wald–Havran's empty-space
  /// bonus; the kd-tree builder uses 0.8). 1 = none, the reference constants.
  double empty_bonus = 1.0;
  int max_depth = 64;         ///< nodes at this depth become leaves
  /// A split must save at least this many expected triangle tests per ray over
  /// the whole tree: (leaf cost − split cost)/C_isect · area(cell)/area(root).
  /// The local SAH is scale-invariant, so around a vertex shared by several
  /// triangles it keeps zooming in forever (every smaller cell still holds all
  /// of them); this absolute bound stops it. 0 = pure local SAH.
  double min_gain = 1e-5;
  /// min_gain limits every split of a node of at most this many triangles, and
  /// in larger nodes only the splits that leave one child with all of them
  /// (the zoom). Without the exception a small, dense cluster in a large scene
  /// (conference: 1,696 tiny triangles of a chair's fitting) stays one leaf,
  /// since the uniform-ray measure sees little gain there, while rays aimed at
  /// vertices test all of it. SIZE_MAX = min_gain everywhere (the old rule).
  std::size_t min_gain_triangles = 8;
  /// Evaluate face/edge (BSP) candidates only when the node holds at most this
  /// many triangles. Above it C_BSP ≥ 7.5·N so kd splits almost always win and
  /// the O(N²)-ish BSP evaluation is wasted (docs/bsp-build.md "Costs";
  /// leave out what a scene does not need). A larger node that no kd split can
  /// refine gets them too, before it is made a leaf (bsp_build.cpp). 0 = kd-tree
  /// only; SIZE_MAX = the paper's full BSP.
  std::size_t bsp_max_triangles = 48;
  /// Count BSP candidates with the bounding-sphere hierarchy (bsh.h) when the
  /// node holds at least this many triangles; below it, a flat sphere list.
  std::size_t bsh_min_triangles = 32;
  bool kd_candidates = true;    ///< axis-aligned planes at the clipped triangles' bounds
  /// With kd_candidates: for a triangle in an axis plane x_a = c, also the
  /// planes one float step either side of c (2^-60 when |c| < 2^-60), so that
  /// a split can keep the triangle in a thin slab and leave the space beside
  /// it empty. Without them a floor or a wall that lies on its cell's boundary
  /// (after the split through its own plane) stays listed in a cell of any
  /// depth: no other candidate lies strictly inside that cell on that axis.
  /// The kd-tree builder tries the planes one step either side of every event
  /// (kd_events.cpp). docs/bsp-build.md, "Slabs around axis-planar triangles".
  bool planar_slabs = true;
  bool face_candidates = true;  ///< each triangle's face plane
  bool edge_candidates = true;  ///< the three planes through a triangle's edges, orthogonal to it
  BspMembership membership = BspMembership::Area;  ///< see BspMembership (Area: the paper's one-triangle leaves)
  /// A triangle lying in a split plane touches both closed children. false
  /// (default): the cheaper side only, as the paper — correct with closed-cell
  /// traversal (a ray hitting it crosses the plane, so it visits both sides),
  /// and essential with the Area rule: listing a ground plane in both children
  /// of the split through it keeps it in every leaf above it (measured on the
  /// default scene: 14.4 vs 0.67 triangle tests per primary ray). true: both
  /// sides (the literal invariant of issue 4).
  bool coplanar_to_both = false;
  int threads = 0;                              ///< worker threads; 0 = all cores
  std::size_t parallel_min_triangles = 2048;    ///< build both subtrees in parallel above this
  int max_split_attempts = 3;                   ///< best candidates tried exactly before a leaf
};

/// Which closed children a clipped triangle reaches against a split plane.
enum class Reach : std::uint8_t { Left, Right, Both, Coplanar };

/// The membership rule applied to a clipped triangle's side summary.
inline Reach reach(const SideSummary& s, BspMembership m) {
  if (s.coplanar()) return Reach::Coplanar;
  const bool l = m == BspMembership::Closed ? (s.neg || s.zero) : s.neg;
  const bool r = m == BspMembership::Closed ? (s.pos || s.zero) : s.pos;
  return l && r ? Reach::Both : (l ? Reach::Left : Reach::Right);
}

}  // namespace bsprt
