#pragma once
/// \file exact_sum.h
/// The exact sign of a short sum of doubles, and rule (c) of the exact leaf test:
/// the exact Plücker volume of a ray with an axis-parallel edge
/// (docs/exact-leaf-test.md, "Rules on exact zeros"). Heap-free and without
/// CGAL: a product of two floats is exact in double, and a sum of such
/// products is summed exactly into a floating-point expansion (Shewchuk,
/// "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
/// Predicates", 1997: Two-Sum and Grow-Expansion). Tested against
/// CGAL::Exact_rational ("exact sum: ..." in tests/test_exact_leaf.cpp).

#include <array>
#include <cmath>

#include "bsprt/vec3.h"

namespace bsprt::detail {

/// Knuth's Two-Sum: x + y = a + b exactly, x = fl(a + b) (no overflow).
inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a, av = x - bv;
  y = (a - av) + (b - bv);
}

/// The sign (-1, 0, +1) of x[0] + ... + x[N-1], exactly, for finite doubles
/// whose sum and partial sums do not overflow. Grow-Expansion adds each term
/// to a nonoverlapping expansion (components in increasing magnitude, zeros
/// anywhere); the sum has the sign of its largest nonzero component.
/// `approx` gets the components added from the smallest up: the sum in
/// double, with that sign.
template <std::size_t N>
inline int exact_sum_sign(const std::array<double, N>& x, double& approx) {
  std::array<double, N> h{};
  std::size_t m = 0;
  for (const double term : x) {
    double q = term;
    for (std::size_t k = 0; k < m; ++k) two_sum(q, h[k], q, h[k]);
    h[m++] = q;
  }
  approx = 0.0;
  for (const double c : h) approx += c;
  for (std::size_t k = N; k-- > 0;)
    if (h[k] != 0.0) return h[k] > 0.0 ? 1 : -1;
  return 0;
}

/// Component j of (p - o) x d as four products of floats, each exact in
/// double: p[a] d[b] - o[a] d[b] - p[b] d[a] + o[b] d[a] (a = j + 1, b = j + 2, mod 3).
inline std::array<double, 4> cross_terms(const Vec3f& p, const Vec3f& o, const Vec3f& d, int j) {
  const int a = (j + 1) % 3, b = (j + 2) % 3;
  return {double(p[a]) * double(d[b]), -(double(o[a]) * double(d[b])), -(double(p[b]) * double(d[a])),
          double(o[b]) * double(d[a])};
}

/// Rule (a): whether the point p lies exactly on the line o + t d, at any t:
/// (p - o) x d = 0, each component an exact sum of four float products. Then
/// the two volumes that pair p with the other corners are exactly 0.
inline bool on_line_exactly(const Vec3f& p, const Vec3f& o, const Vec3f& d) {
  for (int j = 0; j < 3; ++j) {
    double approx;
    if (exact_sum_sign(cross_terms(p, o, d, j), approx) != 0) return false;
  }
  return true;
}

/// Rule (c): the exact sign of the Plücker volume ((P - o) x (Q - o))·d of
/// the ray o + t d with the edge PQ, when P and Q differ in one coordinate j
/// only; false for any other edge. The volume equals (Q - P)·(d x (P - o)),
/// which for such an edge is (Q[j] - P[j]) (d x (P - o))[j], and
/// (d x (P - o))[j] = -((P - o) x d)[j] is a sum of four products of floats
/// (cross_terms), each exact in double (24 + 24 bits; no overflow or
/// underflow for finite floats). `approx` gets the volume in
/// double, for the barycentrics.
inline bool axis_edge_volume_sign(const Vec3f& p, const Vec3f& q, const Vec3f& o, const Vec3f& d, int& sign,
                                  double& approx) {
  int j;
  if (p.y == q.y && p.z == q.z) j = 0;
  else if (p.x == q.x && p.z == q.z) j = 1;
  else if (p.x == q.x && p.y == q.y) j = 2;
  else return false;
  // (d x (p - o))[j] = -((p - o) x d)[j]
  double c;
  const int edge = q[j] > p[j] ? 1 : (q[j] < p[j] ? -1 : 0);
  sign = -edge * exact_sum_sign(cross_terms(p, o, d, j), c);
  approx = (double(q[j]) - double(p[j])) * -c;
  return true;
}

/// The Plücker volume ((P - o) x (Q - o))·d of the ray o + t d with the edge
/// PQ in double from the edge: (Q - P)·(d x (P - o)), with a static bound.
/// The double stage (exact_double_stage.h) computes the volumes from the
/// corners' offsets, so its bound grows with |P - o|^2; this one grows with
/// |Q - P| |d| |P - o|, which settles the small triangles far from the origin
/// that the double stage leaves open. Each of e = Q - P and a = P - o is
/// rounded once, each product of the cross and dot products once, and the
/// sums; the error is below 7.1 u M with u = 2^-53 and M the sum of
/// |e_j| (|d_a| |a_b| + |d_b| |a_a|), computed in double. The bound 2^-48 M
/// is more than four times that. Nothing underflows: a nonzero difference of
/// floats is at least 2^-149, so a nonzero product of three is at least
/// 2^-447. Returns +1 or -1 when the bound decides the sign, else 2; `vol`
/// and `bound` get the volume and the bound.
inline int edge_volume_filter(const Vec3f& p, const Vec3f& q, const Vec3f& o, const Vec3f& d, double& vol,
                              double& bound) {
  double e[3], a[3], c[3], m = 0.0;
  for (int j = 0; j < 3; ++j) e[j] = double(q[j]) - double(p[j]), a[j] = double(p[j]) - double(o[j]);
  vol = 0.0;
  for (int j = 0; j < 3; ++j) {
    const int ja = (j + 1) % 3, jb = (j + 2) % 3;
    c[j] = double(d[ja]) * a[jb] - double(d[jb]) * a[ja];
    vol += e[j] * c[j];
    m += std::abs(e[j]) * (std::abs(double(d[ja]) * a[jb]) + std::abs(double(d[jb]) * a[ja]));
  }
  bound = 0x1p-48 * m;
  return vol > bound ? 1 : (vol < -bound ? -1 : 2);
}

}  // namespace bsprt::detail
