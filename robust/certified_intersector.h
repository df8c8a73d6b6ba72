#pragma once
/// \file certified_intersector.h
/// Ray/triangle tests whose every decision is exact: hit or miss, t inside
/// [tnear, tfar], the float nearest to the exact t, and which of two hits is
/// nearer. Staged (docs/exact-leaf-test.md):
///  1. a double filter with a static error bound decides almost every test;
///  2. rules on exact zeros decide what a filter never can: a vertex exactly on
///     the ray's line (two weights are then exactly 0), and ties between hits
///     at the same vertex, on the same edge or of triangles with the same corners;
///  3. what is left is computed exactly in CGAL::Mpzf, without division and
///     without rationals: signs of the weights, t against tnear and tfar, the
///     rounding of t to float (comparisons with midpoints of floats), and two
///     hits' t compared as num1 * den2 against num2 * den1.
///
/// The test is Plücker-style: with A_i = v_i - o, the signed volumes
/// U = (A1 x A2)·d, V = (A2 x A0)·d, W = (A0 x A1)·d have one sign when the
/// line meets the triangle (zeros on its edges and corners), and
/// t = n·A0 / n·d with n = (v1 - v0) x (v2 - v0) (n·d = U + V + W). A ray lying
/// in the triangle's plane (U = V = W = 0) does not hit it, as in the
/// watertight test. A hit whose exact t rounds to +inf, beyond the float
/// range, is a miss, as in every mode (formats.md: a miss is t = +inf).

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "geometry/core/triangle_soup.h"
#include "traverse/leaf_intersector.h"
#include "traverse/accelerator.h"

namespace bsprt {

/// Exact-decision leaf test over one triangle soup (held by reference).
class CertifiedIntersector final : public LeafIntersector {
 public:
  explicit CertifiedIntersector(const TriangleSoup& soup);
  std::string name() const override { return "certified"; }
  using LeafIntersector::intersect;
  void intersect(const Ray& ray, std::span<const std::uint32_t> prims, const LeafTriangle* corners,
                 NearestHit& best, RayCounters* counters) const override;

  /// A crossing of a ray with a triangle (crossings()).
  struct Crossing {
    std::uint32_t prim;  ///< triangle number
    float t;             ///< the exact t rounded to float
    int side;            ///< +1 or -1: the sign of n·d with n = (v1 - v0) x (v2 - v0)
  };
  /// Appends every triangle of `prims` that the ray crosses with t in
  /// [tnear, tfar], exactly, with simulation of simplicity for exact zeros (the
  /// origin moved to o + (e, e^2, e^3)): a ray through a shared edge or vertex
  /// of a closed, consistently oriented mesh crosses exactly one triangle of
  /// each sheet it passes through, and one that only touches a sheet crosses it
  /// zero or two times. A ray in a triangle's plane does not cross it. Corners
  /// are read from the scene. Counts as intersect() does.
  void crossings(const Ray& ray, std::span<const std::uint32_t> prims, std::vector<Crossing>& out,
                 RayCounters* counters) const;

  /// Decisions the filter and the rules could not make, done in exact
  /// arithmetic (all threads; one shared counter, added once per call).
  std::uint64_t exact_fallbacks() const { return fallbacks_.load(std::memory_order_relaxed); }

  /// Tests only, single-threaded: the weights (bit k: the weight of v_k)
  /// whose signs the double filter decided are decided again by the rules and
  /// the exact stage (a miss from two opposite filtered signs stays a miss), so
  /// tests can check that filtered and exact signs mix correctly. 0 = off. Global.
  static void set_filter_off_for_testing(unsigned weights);

 private:
  const TriangleSoup& soup_;
  mutable std::atomic<std::uint64_t> fallbacks_{0};
};

/// Brute force with the certified test: every triangle, exact decisions. The
/// float structure-free reference that the certified tree tracers must equal.
class CertifiedBruteTracer final : public Accelerator {
 public:
  explicit CertifiedBruteTracer(const TriangleSoup& soup);
  std::string name() const override { return "brute-certified"; }
  Hit trace(const Ray& ray, RayCounters* counters = nullptr) const override;
  const CertifiedIntersector& intersector() const { return intersector_; }

 private:
  const TriangleSoup& soup_;
  CertifiedIntersector intersector_;
  std::vector<std::uint32_t> live_;  ///< non-degenerate triangles
};

}  // namespace bsprt
