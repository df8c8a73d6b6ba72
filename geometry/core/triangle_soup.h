#pragma once
/// \file triangle_soup.h
/// The flat scene representation every stage shares: float vertices and index
/// triples, numbered as in shared/formats.md (faces in file order, polygons fan
/// triangulated). Degenerate triangles keep their numbers and are flagged.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "bsprt/vec3.h"

namespace bsprt {

/// Three vertex indices into TriangleSoup::vertices.
using TriIndices = std::array<std::uint32_t, 3>;

/// A triangle soup: no connectivity is assumed, duplicates and non-manifold
/// configurations are legal, nothing is ever dropped.
struct TriangleSoup {
  std::vector<Vec3f> vertices;
  std::vector<TriIndices> triangles;
  /// degenerate[i] != 0 when triangle i has repeated or collinear corners (exact
  /// test) or a non-finite corner; such triangles are never hit. Same size as
  /// `triangles` once `classify_degenerate` has run.
  std::vector<std::uint8_t> degenerate;

  std::size_t size() const { return triangles.size(); }
  /// Corner k (0..2) of triangle t.
  const Vec3f& corner(std::uint32_t t, int k) const { return vertices[triangles[t][k]]; }
  std::array<Vec3f, 3> corners(std::uint32_t t) const {
    return {corner(t, 0), corner(t, 1), corner(t, 2)};
  }
  bool is_degenerate(std::uint32_t t) const { return !degenerate.empty() && degenerate[t] != 0; }
  /// Unit normal of triangle t, (b - a) x (c - a) normalized, made in double: in
  /// float the cross product of a triangle near 2^-130 underflows to zero and its
  /// normal became NaN (shading). NaN for a degenerate triangle.
  Vec3f unit_normal(std::uint32_t t) const {
    const Vec3d a(corner(t, 0)), b(corner(t, 1)), c(corner(t, 2));
    return Vec3f(normalize(cross(b - a, c - a)));
  }
  /// Bounds of the corners of all non-degenerate triangles (unreferenced vertices
  /// do not count).
  Box3f bounds() const;
  /// Number of triangles flagged degenerate.
  std::size_t degenerate_count() const;
  /// Number of vertices no triangle uses (they are kept, never looked at).
  std::size_t unreferenced_vertex_count() const;
};

/// Appends every triangle of `b` (vertices re-indexed) to `a`.
void append(TriangleSoup& a, const TriangleSoup& b);

/// `s` with every triangle listed twice: triangle n + i is triangle i with
/// reversed winding (corners 0, 2, 1), on the same vertices, with its flag.
/// Coplanar duplicates that every ray meets at the same t: the scene spec
/// "twin:FILE" (docs/exact-leaf-test.md, "Rules on exact zeros").
TriangleSoup with_reversed_copies(const TriangleSoup& s);

}  // namespace bsprt
