#pragma once
/// \file bsh.h
/// Counting with a bounding-sphere hierarchy (docs/bsp-build.md "Counting";
/// Ize, Wald, Parker, RT 2008, §3.3 and future work): for a candidate plane the
/// SAH needs how many of the node's clipped triangles reach each child. A BVH of
/// bounding spheres over the clipped triangles answers it without touching every
/// triangle: a sphere wholly on one side counts its subtree at once, straddling
/// spheres recurse, leaves classify their triangles exactly (exact_polygon.h).
///
/// The sphere test is rigorous, not a heuristic with a margin: radii are rounded
/// up, the plane value at the centre is an interval, and |n| is bounded above, so
/// "wholly on one side" is certain and the counts equal the exact per-triangle
/// counts. Built per node (O(N log N)); the tree is rebuilt for each child.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "builder/bsp/bsp_config.h"
#include "robust/exact_polygon.h"

namespace bsprt {

/// A sphere that certainly contains what it bounds (radius rounded up).
struct Sphere {
  std::array<double, 3> c{};
  double r = 0;
};

/// How many clipped triangles reach each closed child of a plane.
struct SplitCount {
  std::size_t left = 0;      ///< only the left child
  std::size_t right = 0;     ///< only the right child
  std::size_t both = 0;      ///< both children (straddling or touching the plane)
  std::size_t coplanar = 0;  ///< lying in the plane (placed by the coplanar rule)
  void add(Reach r, std::size_t n = 1) {
    (r == Reach::Left ? left : r == Reach::Right ? right : r == Reach::Both ? both : coplanar) += n;
  }
};

/// The sphere around a box (centre at its middle, radius rounded up).
Sphere bounding_sphere(const RoundingGuard& g, const Box3d& b);

/// +1 when the sphere lies strictly on the positive side, −1 strictly negative, 0 otherwise.
int sphere_side(const RoundingGuard& g, const PreparedPlane& p, const Sphere& s);

/// A bounding-sphere hierarchy over one node's clipped triangles.
class Bsh {
 public:
  /// Builds over `tris` (kept by reference: must outlive the Bsh). leaf_size ≥ N
  /// gives a flat list of spheres (the naive count with a sphere pre-test).
  Bsh(const RoundingGuard& g, const std::vector<ClippedTriangle>& tris, std::size_t leaf_size = 4);

  /// Exact counts of the triangles reaching each child of `plane`.
  SplitCount count(const RoundingGuard& g, const TriangleSoup& soup, const PreparedPlane& plane,
                   BspMembership m, ExactStats& stats) const;

  /// Sphere tests and exact triangle classifications done so far (scaling studies).
  std::uint64_t sphere_tests() const { return sphere_tests_; }
  std::uint64_t triangle_tests() const { return triangle_tests_; }

 private:
  struct Node {
    Sphere s;
    std::uint32_t first = 0;  ///< leaf: first index into order_; inner: left child
    std::uint32_t count = 0;  ///< leaf: triangle count; inner: 0
    std::uint32_t right = 0;  ///< inner: right child
    std::uint32_t total = 0;  ///< triangles below
  };
  std::uint32_t build(const RoundingGuard& g, std::uint32_t begin, std::uint32_t end,
                      std::vector<Box3d>& boxes, std::size_t leaf_size);

  const std::vector<ClippedTriangle>& tris_;
  std::vector<Node> nodes_;
  std::vector<std::uint32_t> order_;
  std::vector<Sphere> spheres_;
  mutable std::uint64_t sphere_tests_ = 0;
  mutable std::uint64_t triangle_tests_ = 0;
};

}  // namespace bsprt
