#pragma once
/// \file inside_query.h
/// Whether points lie inside a closed triangle mesh, exactly: on the surface
/// when a (closed, non-degenerate) triangle contains the point, else by the
/// parity of the crossings of a ray from the point, decided by the exact leaf
/// test with simulation of simplicity (CertifiedIntersector::crossings), so a
/// ray through a vertex or an edge counts each sheet once. Candidates come from
/// the exact reference's AABB tree. docs/exact-leaf-test.md, "Inside queries".

#include <cstdint>
#include <string>
#include <vector>

#include "bsprt/query.h"
#include "geometry/core/triangle_soup.h"
#include "robust/certified_intersector.h"
#include "robust/exact_tracer.h"

namespace bsprt {

// PointSide (Outside, Inside, OnSurface) is the public API's (bsprt/query.h).

/// "outside", "inside", "surface".
std::string point_side_name(PointSide s);

/// Edges of non-degenerate triangles (by vertex position) used by other than
/// exactly two triangles, or twice in the same direction: 0 for a closed,
/// consistently oriented 2-manifold, where parity is well defined.
std::size_t open_or_inconsistent_edges(const TriangleSoup& soup);

/// The inside query over one scene (held by reference).
class InsideQuery {
 public:
  explicit InsideQuery(const TriangleSoup& soup);
  /// Where p lies. Non-finite points are Outside.
  PointSide side(const Vec3f& p, RayCounters* counters = nullptr) const;
  /// Every crossing of `ray` with t in [tnear, tfar], exactly, appended to
  /// `out` ordered by t, then triangle: what `bsprt trace --all-hits` writes
  /// for one ray. `candidates` is scratch space.
  void crossings(const Ray& ray, std::vector<std::uint32_t>& candidates,
                 std::vector<CertifiedIntersector::Crossing>& out, RayCounters* counters = nullptr) const;
  /// The direction of the parity rays (fixed; any direction gives the same
  /// answers on a closed mesh).
  static Vec3f ray_direction() { return {1.0f, 0.375f, 0.1875f}; }

 private:
  ExactTracer exact_;
  CertifiedIntersector cert_;
};

}  // namespace bsprt
