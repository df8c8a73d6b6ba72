#pragma once
/// \file epsilon_bound.h
/// Certified bounds for the float BSP traversal (docs/certified-epsilons.md).
/// A stored plane has exact coefficients value(x) = n*·(x − r) (plane.h); the
/// traversal uses a float plane F(x) = n_f·x + d_f meant to approximate the
/// scaled exact plane G(x) = s·n*·(x − r) for a chosen s > 0. Over a convex
/// cell, F − G is affine, so max |F − G| is attained at a vertex; evaluating it
/// in interval arithmetic on the vertices' interval enclosures gives a true
/// upper bound δ. (Ize, "Robust BVH Ray Traversal", JCGT 2013, bounds the
/// traversal arithmetic the same way: every rounding accounted, then widened.)

#include <array>
#include <span>

#include "robust/exact_side.h"

namespace bsprt {

/// A float plane F(x) = n·x + d for a stored plane, with the scale s it
/// approximates (G = s·value) and its certified traversal epsilon.
struct FloatPlane {
  std::array<float, 3> n{};  ///< float normal, ‖n‖₂ ≈ 1
  float d = 0.0f;            ///< float offset
  double scale = 1.0;        ///< s: F ≈ s·n*·(x − r)
  double delta = 0.0;        ///< upper bound of |F − G| over the cell's vertices
  float eps = 0.0f;          ///< stored bound: >= delta + u·|d| (docs §2), rounded up
};

/// The float plane of `plane` (s = 1/‖n*‖ in double, n = s·n* and d = −n·r
/// rounded to nearest) and its bound over the convex hull of `vertices`
/// (interval enclosures of the cell's exact vertices). Needs upward rounding.
FloatPlane float_plane_bound(const RoundingGuard& g, const PreparedPlane& plane,
                             std::span<const IntervalBox> vertices);

/// Upper bound of max |(n·x + d) − s·n*·(x − r)| over the given vertex
/// enclosures, evaluated as Σ (n_i − s·n*_i)(x_i − r_i) + (n·r + d) in interval
/// arithmetic (small coefficients times cell-relative coordinates, so scenes
/// far from the origin keep tight bounds). Needs upward rounding.
double plane_rounding_bound(const RoundingGuard& g, const PreparedPlane& plane, double s,
                            const std::array<float, 3>& n, float d,
                            std::span<const IntervalBox> vertices);

/// The per-node epsilon traversal stores: a float >= delta + 2^-23·|d| (the
/// rounding of the last addition of n·o + d), with a relative margin of 2^-20
/// so the float sums of traversal stay above the real bound. Rounded up.
float node_epsilon(double delta, float d);

}  // namespace bsprt
