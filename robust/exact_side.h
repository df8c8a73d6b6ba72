#pragma once
/// \file exact_side.h
/// Exact points and exact side-of-plane tests (docs/bsp-build.md "Exact
/// arithmetic scheme"). A point is the intersection of three stored planes (plane.h), so
/// its exact coordinates are rational functions of the input floats and no
/// construction depends on an earlier construction. Each point carries an
/// interval enclosure of its coordinates; a side test first evaluates the plane
/// in interval arithmetic (CGAL::Interval_nt), then, only when the interval
/// contains 0, exactly from the defining data (CGAL::Mpzf: exact products and
/// sums of doubles, no division). Both stages are counted in ExactStats.
///
/// Interval arithmetic needs the FPU rounding upward; the functions that rely on
/// it take a `const RoundingGuard&` to make that explicit in the types.

#include <array>
#include <cstdint>
#include <limits>

#include "geometry/core/triangle_soup.h"
#include "bsprt/vec3.h"
#include "robust/plane.h"

namespace bsprt {

/// Counters of one build (or one verification): how stiff the scene was.
struct ExactStats {
  std::uint64_t filter_calls = 0;     ///< side tests evaluated in interval arithmetic
  std::uint64_t symbolic = 0;         ///< side tests decided from the definitions alone
  std::uint64_t exact_fallbacks = 0;  ///< side tests the filter could not decide (exact Mpzf)
  std::uint64_t exact_points = 0;     ///< point enclosures recomputed exactly (filter overflow)
  void add(const ExactStats& o) {
    filter_calls += o.filter_calls;
    symbolic += o.symbolic;
    exact_fallbacks += o.exact_fallbacks;
    exact_points += o.exact_points;
  }
};

/// RAII: sets the FPU rounding mode upward (as CGAL::Interval_nt<false> needs) and
/// restores the previous mode. Cheap (two control-register writes); one per batch.
class RoundingGuard {
 public:
  RoundingGuard();
  ~RoundingGuard();
  RoundingGuard(const RoundingGuard&) = delete;
  RoundingGuard& operator=(const RoundingGuard&) = delete;

 private:
  unsigned saved_;
};

/// A closed interval enclosure of a point's coordinates.
struct IntervalBox {
  std::array<double, 3> lo{}, hi{};
  /// True when every coordinate is known exactly (lo == hi).
  bool is_point() const { return lo[0] == hi[0] && lo[1] == hi[1] && lo[2] == hi[2]; }
  /// Midpoint approximation (steering only).
  Vec3d mid() const { return {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])}; }
};

/// The intersection point of three stored planes, with an interval enclosure.
/// Triangle corners are (face, edge k−1, edge k) of their triangle and cell
/// corners of the root box are three Kd planes: both have exact coordinates.
struct ExactPoint {
  std::array<PlaneDef, 3> def{};
  IntervalBox box;
  /// True when `p` is one of the defining planes (the point lies on it exactly).
  bool defined_by(PlaneDef p) const { return def[0] == p || def[1] == p || def[2] == p; }
  /// Double approximation (steering only).
  Vec3d approx() const { return box.mid(); }
};

/// A plane prepared for many side tests: interval normal, exact reference point,
/// the input points known to lie on it (for symbolic zeros), approximation.
struct PreparedPlane {
  PlaneDef def;
  std::array<double, 3> n_lo{}, n_hi{};  ///< enclosure of the exact normal n
  std::array<double, 3> ref{};           ///< exact reference point r (value = n·(p − r))
  std::array<Vec3f, 3> on_points{};      ///< input points lying on the plane by definition
  int on_count = 0;                      ///< how many of on_points are used
  ApproxPlane approx;                    ///< unit-normal approximation (steering)
};

/// Prepares `p` for side tests (needs the rounding guard: interval normal).
PreparedPlane prepare_plane(const RoundingGuard&, const TriangleSoup& soup, PlaneDef p);

/// Corner k of triangle t as an exact point (face, edge k+2, edge k).
ExactPoint corner_point(const TriangleSoup& soup, std::uint32_t t, int k);

/// The point where three planes meet; they must meet in exactly one point (the
/// callers guarantee it combinatorially; checked when the exact path runs).
ExactPoint make_point(const RoundingGuard&, const TriangleSoup& soup, PlaneDef a, PlaneDef b,
                      PlaneDef c, ExactStats& stats);

/// Exact sign (−1, 0, +1) of plane value n·(p − r) at point p: filtered.
int side(const RoundingGuard&, const TriangleSoup& soup, const PreparedPlane& plane,
         const ExactPoint& p, ExactStats& stats);

/// Exact sign of `plane` at a point given by exact double coordinates (no filter).
int exact_side_at(const TriangleSoup& soup, PlaneDef plane, const std::array<double, 3>& p);

/// Exact sign of `plane` at the intersection of the three planes `def`.
int exact_side_at(const TriangleSoup& soup, PlaneDef plane, const std::array<PlaneDef, 3>& def);

/// Exact rational coordinates as (numerators, denominator) doubles is impossible in
/// general; this returns a tight interval enclosure computed from exact values.
IntervalBox exact_enclosure(const TriangleSoup& soup, const std::array<PlaneDef, 3>& def);

/// True when triangle t cannot be hit: a non-finite corner, or its corners are
/// collinear (exact test). Such triangles never enter a BSP node.
bool triangle_degenerate_exact(const TriangleSoup& soup, std::uint32_t t);

}  // namespace bsprt
