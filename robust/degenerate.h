#pragma once
/// \file degenerate.h
/// Exact degeneracy test (CGAL filtered predicates): a triangle is degenerate
/// when two corners coincide or all three are collinear. Such triangles keep
/// their numbers but can never be hit.

#include <cstddef>

#include "geometry/core/triangle_soup.h"

namespace bsprt {

/// True when a, b, c are collinear (including coincident), decided exactly.
/// Non-finite corners count as degenerate.
bool is_degenerate_exact(const Vec3f& a, const Vec3f& b, const Vec3f& c);

/// Sets soup.degenerate for every triangle; returns how many are degenerate.
std::size_t classify_degenerate(TriangleSoup& soup);

}  // namespace bsprt
