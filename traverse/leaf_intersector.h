#pragma once
/// \file leaf_intersector.h
/// How a traversal tests the triangles of a leaf, when the float watertight
/// test is not enough: an exact-decision intersector (robust/certified_*.h,
/// CGAL) plugs in here, so traverse/ never sees CGAL. The interface carries an
/// enclosure of the best hit's exact t so that comparisons between hits, and
/// the traversal's early exit, stay exact.

#include <array>
#include <bit>
#include <cstdint>
#include <limits>
#include <span>
#include <string>

#include "bsprt/ray.h"
#include "traverse/counters.h"

namespace bsprt {

/// The nearest hit so far and a certain enclosure [t_lo, t_hi] of its exact
/// ray parameter (both +inf while there is no hit). Traversal may stop once a
/// node's entry t exceeds t_hi.
struct NearestHit {
  Hit hit;
  double t_lo = std::numeric_limits<double>::infinity();
  double t_hi = std::numeric_limits<double>::infinity();
  /// Where the best hit lies when an exact zero put it on a vertex or an edge
  /// of its triangle: 0 inside (or not known), 1 at vertex p, 2 on edge pq.
  /// Another triangle's hit at the same vertex, or on the same edge, has the
  /// same exact t, which lets a tie be decided without exact arithmetic.
  std::uint8_t on = 0;
  Vec3f p, q;
  /// The best hit's triangle (v0, v1, v2), for ties decided by the corners
  /// alone (detail::same_t_by_corners); set with every new best hit, read
  /// only while there is one. NaN before: no corner equals it. Not zeros:
  /// GCC cleared the all-zero 96 bytes with `rep stos`, once for every ray of
  /// every exact walk, and its start-up cost shows on short rays.
  static constexpr float kNoCorner = std::numeric_limits<float>::quiet_NaN();
  std::array<float, 9> tri{kNoCorner, kNoCorner, kNoCorner, kNoCorner, kNoCorner,
                           kNoCorner, kNoCorner, kNoCorner, kNoCorner};
};

/// The traversal's cull bound for an exact nearest hit: the smallest float at
/// or above t_hi (+inf without a hit). The reported float t may lie below the
/// exact t, and a cell entered between the two can still hold a nearer hit or
/// a tie; culling against this bound never skips such a cell.
inline float cull_bound(const NearestHit& best) {
  if (!best.hit.hit()) return std::numeric_limits<float>::infinity();
  const float f = float(best.t_hi);
  if (!(double(f) < best.t_hi)) return f;
  // The next float up, by its bits (t_hi is finite: f is at most FLT_MAX).
  const std::uint32_t b = std::bit_cast<std::uint32_t>(f);
  if (f == 0.0f) return std::numeric_limits<float>::denorm_min();
  return std::bit_cast<float>(f > 0.0f ? b + 1u : b - 1u);
}

/// A triangle as a traversal stores it beside its leaves: its three corners.
struct LeafTriangle {
  Vec3f v[3];
};

/// Tests only, single-threaded (CertifiedIntersector::set_filter_off_for_testing):
/// bit k set sends weight k to the rules and the exact stage even when the
/// double filter decided it; while it is non-zero, traversals call the
/// intersector for every triangle (exact_double_stage.h). 0 = off.
inline unsigned exact_filter_off_for_testing = 0;

/// Tests leaf triangles with exact decisions; thread-safe, stateless per call.
class LeafIntersector {
 public:
  virtual ~LeafIntersector() = default;
  /// True when every triangle that the inline double stage of
  /// exact_double_stage.h decides is decided by intersect() the same way, so
  /// a traversal may decide those itself (detail::exact_leaf_staged) and call
  /// intersect() for the rest only.
  bool staged() const { return staged_; }
  /// Short name for reports ("certified").
  virtual std::string name() const = 0;
  /// Tests the triangles `prims` (triangle numbers of the scene it was made
  /// for) against `ray`, keeping the exactly nearest one in `best` (exact ties
  /// go to the lower triangle number). Counts triangle_tests when non-null.
  /// `corners`, when non-null, holds the corners of prims[i] at corners[i]
  /// (the traversal's own copy, read in leaf order); else the intersector
  /// reads them from its scene.
  virtual void intersect(const Ray& ray, std::span<const std::uint32_t> prims, const LeafTriangle* corners,
                         NearestHit& best, RayCounters* counters) const = 0;
  /// As above, corners from the scene.
  void intersect(const Ray& ray, std::span<const std::uint32_t> prims, NearestHit& best,
                 RayCounters* counters) const {
    intersect(ray, prims, nullptr, best, counters);
  }

 protected:
  bool staged_ = false;  ///< see staged()
};

}  // namespace bsprt
