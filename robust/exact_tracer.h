#pragma once
/// \file exact_tracer.h
/// The exact reference tracer: the nearest hit of each float ray, decided with
/// exact arithmetic (CGAL). Candidates come from a CGAL AABB tree whose
/// predicates are exact (Epick's filtered do_intersect), and each candidate's
/// ray parameter is computed exactly (Epeck) and compared exactly, so the
/// reported triangle is the true nearest one; t, u, v are the exact values
/// rounded to float. Slow compared with the float tracers: a reference, used by
/// tests, `bsprt bench` and `bsprt compare`.

#include <cstdint>
#include <memory>
#include <vector>

#include "geometry/core/triangle_soup.h"
#include "traverse/accelerator.h"

namespace bsprt {

/// Exact nearest-hit oracle. A ray lying in a triangle's plane and crossing it
/// hits it at the nearest point of the overlap. Ties in exact t (a shared edge
/// or vertex) go to the lowest triangle number. Degenerate triangles never hit.
class ExactTracer final : public Accelerator {
 public:
  /// Holds a reference: `soup` must outlive the tracer.
  explicit ExactTracer(const TriangleSoup& soup);
  ~ExactTracer() override;
  std::string name() const override { return "exact"; }
  Hit trace(const Ray& ray, RayCounters* counters = nullptr) const override;
  std::size_t memory_bytes() const override;
  /// The non-degenerate triangles whose closed triangle the ray touches, by
  /// the AABB tree's exact predicates (tnear >= 0: the ray from the origin, else
  /// the whole line; every triangle when no exact query exists). A superset of
  /// the triangles hit with t in [tnear, tfar].
  void touched(const Ray& ray, std::vector<std::uint32_t>& prims) const;
  /// Whether p lies on a non-degenerate triangle (closed), exactly.
  bool on_surface(const Vec3f& p) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bsprt
