#pragma once
/// \file leaf_intersector.h
/// How a traversal tests the triangles of a leaf, when the float watertight
/// test is not enough: an exact-decision intersector (robust/certified_*.h,
/// CGAL) plugs in here, so traverse/ never sees CGAL. The interface carries an
/// enclosure of the best hit's exact t so that comparisons between hits, and
/// the traversal's early exit, stay exact.

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
};

/// Tests leaf triangles with exact decisions; thread-safe, stateless per call.
class LeafIntersector {
 public:
  virtual ~LeafIntersector() = default;
  /// Short name for reports ("certified").
  virtual std::string name() const = 0;
  /// Tests the triangles `prims` (triangle numbers of the scene it was made
  /// for) against `ray`, keeping the exactly nearest one in `best` (exact ties
  /// go to the lower triangle number). Counts triangle_tests when non-null.
  virtual void intersect(const Ray& ray, std::span<const std::uint32_t> prims, NearestHit& best,
                         RayCounters* counters) const = 0;
};

}  // namespace bsprt
