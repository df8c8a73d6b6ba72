#pragma once
/// \file verify.h
/// `bsprt verify`: an independent exact checker of a BSP tree file
/// (docs/verify.md). It shares no arithmetic with the builder (no Cell::split,
/// no exact_side, no clipping code of robust/exact_polygon): planes, points
/// and side tests are re-derived here from the input floats with
/// CGAL::Interval_nt as a filter and CGAL::Mpzf (exact dyadic ring arithmetic,
/// homogeneous coordinates, no division) when the filter cannot decide.
///
/// It proves, for the arrays as written in the file (VerifyInput):
///  (a) tiling: every split plane cuts its node's cell strictly (exact
///      vertices on both sides), so the children are the two closed halves of
///      the parent and the leaves tile the root box (volumes are summed as a
///      cross-check in interval arithmetic);
///  (b) membership: the recorded rule (Closed / Area, coplanar_to_both) holds
///      for every (triangle, leaf) pair, and every point of every
///      non-degenerate triangle lies in the closed cell of a leaf listing it;
///  (c) every float plane node's eps covers its float plane over the exact
///      children cells, and the flat tree is the flatten order of the exact one;
///  (d) structure: ids in range, every node reached once, no degenerate
///      triangle listed.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "geometry/core/triangle_soup.h"
#include "robust/plane.h"
#include "traverse/bsp/bsp_node.h"

namespace bsprt {

/// One exact node as stored in the file (BNOD, 12 bytes; builder/bsp_tree.h).
struct VerifyNode {
  static constexpr std::uint32_t kLeaf = 0xFFFFFFFFu;
  std::uint32_t plane = kLeaf;  ///< plane table index, or kLeaf
  std::uint32_t a = 0;          ///< inner: left child; leaf: first ref
  std::uint32_t b = 0;          ///< inner: right child; leaf: ref count
};

/// The raw contents of a BSP tree file, nothing validated (builder/verify_file.h reads it).
struct VerifyInput {
  Box3f root_box;                       ///< BHDR root box
  std::uint32_t membership = 0;         ///< BHDR membership (0 Closed, 1 Area)
  bool coplanar_to_both = true;         ///< BHDR flags bit 0
  std::vector<PlaneDef> planes;         ///< BPLN
  std::vector<VerifyNode> nodes;        ///< BNOD
  std::vector<std::uint32_t> refs;      ///< BREF
  bool has_flat = false;                ///< FHDR/FNOD/FPRM present
  Box3f flat_box;                       ///< FHDR root box
  std::uint32_t flat_triangle_count = 0;  ///< FHDR triangle count
  std::vector<FlatBspNode> flat_nodes;  ///< FNOD
  std::vector<std::uint32_t> flat_prims;  ///< FPRM
};

/// Options of verify_bsp.
struct VerifyConfig {
  int threads = 0;  ///< worker threads; 0 = all cores
  /// Spawn a parallel task for a subtree holding at least this many pieces.
  std::size_t parallel_min_pieces = 256;
  /// Treat listings of triangles that do not touch the leaf's closed cell as
  /// failures (the builder never writes them); default: count them as warnings.
  bool strict_extras = false;
  /// Called with (leaves done, leaves total), from any thread.
  std::function<void(std::uint64_t, std::uint64_t)> progress;
};

/// The first counter-example found.
struct VerifyFailure {
  std::string what;                  ///< which property failed, in words
  std::uint32_t node = 0xFFFFFFFFu;  ///< exact node id (BNOD index), if any
  std::uint32_t triangle = 0xFFFFFFFFu;  ///< triangle id, if any
  std::uint32_t flat_node = 0xFFFFFFFFu;  ///< flat slot id (FNOD index), if any
  std::optional<Vec3d> witness;      ///< a point showing it (rounded to double)
  /// One line: what, node, triangle, witness.
  std::string describe() const;
};

/// What verify_bsp proved, with its cost.
struct VerifyReport {
  bool certified = false;          ///< every check passed
  std::optional<VerifyFailure> failure;  ///< the first counter-example (lowest node id found)
  std::string membership;          ///< "closed" or "area"
  bool coplanar_to_both = true;
  std::uint64_t nodes = 0, leaves = 0, triangles = 0;  ///< checked
  std::uint64_t pairs = 0;          ///< (triangle, leaf) pairs decided
  std::uint64_t required_pairs = 0; ///< pairs the rule requires to be listed
  std::uint64_t extra_listings = 0; ///< listed but not touching the closed cell (warning)
  std::uint64_t boundary_listings = 0;  ///< Area rule: listed, touching with zero area (allowed)
  std::uint64_t degenerate_triangles = 0;  ///< in the scene (must not be listed)
  std::uint64_t flat_plane_nodes = 0, flat_kd_nodes = 0;  ///< flat nodes checked
  /// Max over plane nodes and child vertices of (F + 2^-23|d|)(1 + 2^-20)/eps,
  /// from the vertices' interval boxes (an upper estimate: may exceed 1 where
  /// the exact test then decided).
  double max_eps_use = 0.0;
  /// Upper bound of |Σ leaf volumes − root volume| / root volume (interval
  /// arithmetic: a cross-check; verification fails only if the interval
  /// proves the volumes differ). NaN when the walk stopped at a failure.
  double volume_rel_error = 0.0;
  std::uint64_t filter_tests = 0;   ///< interval side tests
  std::uint64_t exact_fallbacks = 0;  ///< side tests decided in exact arithmetic
  std::uint64_t exact_points = 0;   ///< points constructed exactly
  double seconds = 0.0;
  std::vector<std::string> notes;   ///< e.g. "no flat sections: (c) skipped"
};

/// Verifies a BSP tree file's contents against `soup`. Never throws for a bad
/// tree: the report carries the first counter-example.
VerifyReport verify_bsp(const TriangleSoup& soup, const VerifyInput& in, const VerifyConfig& options = {});

}  // namespace bsprt
