#pragma once
/// \file kd_clip.h
/// Conservative bounds of a triangle clipped to a box, for perfect splits
/// (Wald and Havran 2006, Sec. 4.1). Computed in double with Sutherland-Hodgman
/// and rounded outward, so the returned box always contains the exact
/// intersection of the triangle with the closed box: a triangle is never lost.

#include <array>

#include "bsprt/vec3.h"

namespace bsprt {

/// Bounds of (triangle ∩ closed `box`) in float, never smaller than the exact
/// set's bounds and never larger than box ∩ bounds(triangle). Returns false only
/// when the exact intersection is provably empty.
///
/// Why it is conservative: each clipping plane is pushed outward by a margin m
/// larger than the error any computed polygon vertex can carry (every new vertex
/// is one interpolation of two earlier ones, error <= delta = 2^-44 * scale,
/// at most six in a chain), so no point of the exact polygon is cut away; the
/// computed bounds of generated vertices are then widened by m and rounded
/// outward to float, and clamped to box ∩ bounds(triangle), which contain the
/// exact set. Corners of the input triangle are exact and never widened.
bool clip_triangle_bounds(const std::array<Vec3f, 3>& tri, const Box3f& box, Box3f& out);

}  // namespace bsprt
