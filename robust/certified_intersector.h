#pragma once
/// \file certified_intersector.h
/// Ray/triangle tests whose every decision is exact: hit or miss, t inside
/// [tnear, tfar], and which of two hits is nearer. Filtered (docs/bsp-build.md,
/// "Exact arithmetic scheme"): interval arithmetic (CGAL::Interval_nt)
/// decides almost always; exact rationals (CGAL::Exact_rational) run only when
/// an interval straddles zero, and are counted.
///
/// The test is Plücker-style: with A_i = v_i - o, the signed volumes
/// U = (A1 x A2)·d, V = (A2 x A0)·d, W = (A0 x A1)·d have one sign when the
/// line meets the triangle (zeros on its edges and corners); the hit point is
/// (U A0 + V A1 + W A2)/(U+V+W) + o, so t = (U z0 + V z1 + W z2)/((U+V+W) d·d)
/// with z_i = A_i·d. A ray lying in the triangle's plane (U = V = W = 0) does
/// not hit it, as in the watertight test.

#include <atomic>
#include <cstdint>
#include <memory>

#include "geometry/core/triangle_soup.h"
#include "traverse/leaf_intersector.h"
#include "traverse/accelerator.h"

namespace bsprt {

/// Exact-decision leaf test over one triangle soup (held by reference).
class CertifiedIntersector final : public LeafIntersector {
 public:
  explicit CertifiedIntersector(const TriangleSoup& soup);
  std::string name() const override { return "certified"; }
  void intersect(const Ray& ray, std::span<const std::uint32_t> prims, NearestHit& best,
                 RayCounters* counters) const override;

  /// Decisions the interval filter could not make, done in exact rationals
  /// (all threads; rare, so one shared counter costs nothing).
  std::uint64_t exact_fallbacks() const { return fallbacks_.load(std::memory_order_relaxed); }

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
