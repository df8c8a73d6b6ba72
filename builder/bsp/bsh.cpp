/// \file bsh.cpp
/// Bounding-sphere hierarchy: median build, rigorous sphere tests, exact leaves.
#include "builder/bsp/bsh.h"

#include <CGAL/Interval_nt.h>

#include <algorithm>
#include <cmath>

namespace bsprt {

namespace {
using IA = CGAL::Interval_nt<false>;
}  // namespace

Sphere bounding_sphere(const RoundingGuard&, const Box3d& b) {
  // Rounding is upward here (the guard), so every step overestimates r.
  Sphere s;
  double r2 = 0;
  for (int i = 0; i < 3; ++i) {
    s.c[i] = 0.5 * b.lo[i] + 0.5 * b.hi[i];
    const double e = std::max(b.hi[i] - s.c[i], s.c[i] - b.lo[i]);
    r2 += e * e;
  }
  s.r = std::sqrt(r2);
  return s;
}

int sphere_side(const RoundingGuard&, const PreparedPlane& p, const Sphere& s) {
  // A sphere of a box whose approximate bounds overflowed (scenes near 1e38)
  // decides nothing; CGAL's Interval_nt asserts on an infinite endpoint
  // (found by the sanitizer run of CI, 2026-12-07).
  if (!std::isfinite(s.r) || !std::isfinite(s.c[0]) || !std::isfinite(s.c[1]) || !std::isfinite(s.c[2])) return 0;
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(p.n_lo[i]) || !std::isfinite(p.n_hi[i]) || !std::isfinite(p.ref[i])) return 0;
  IA v(0.0), nn(0.0);
  for (int i = 0; i < 3; ++i) {
    const IA n(p.n_lo[i], p.n_hi[i]);
    v += n * (IA(s.c[i]) - p.ref[i]);
    nn += CGAL::square(n);
  }
  const double reach = s.r * std::sqrt(nn.sup());  // upward: ≥ r·|n|
  if (!std::isfinite(reach)) return 0;
  if (v.inf() > reach) return 1;
  if (-v.sup() > reach) return -1;
  return 0;
}

Bsh::Bsh(const RoundingGuard& g, const std::vector<ClippedTriangle>& tris, std::size_t leaf_size)
    : tris_(tris) {
  const std::uint32_t n = static_cast<std::uint32_t>(tris.size());
  std::vector<Box3d> boxes(n);
  spheres_.resize(n);
  order_.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    boxes[i] = tris[i].bounds();
    spheres_[i] = bounding_sphere(g, boxes[i]);
    order_[i] = i;
  }
  if (n > 0) build(g, 0, n, boxes, std::max<std::size_t>(1, leaf_size));
}

std::uint32_t Bsh::build(const RoundingGuard& g, std::uint32_t begin, std::uint32_t end,
                         std::vector<Box3d>& boxes, std::size_t leaf_size) {
  Box3d b;
  for (std::uint32_t i = begin; i < end; ++i) b.extend(boxes[order_[i]]);
  const std::uint32_t id = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back({});
  nodes_[id].s = bounding_sphere(g, b);
  nodes_[id].total = end - begin;
  if (end - begin <= leaf_size) {
    nodes_[id].first = begin;
    nodes_[id].count = end - begin;
    return id;
  }
  const int axis = max_axis(b.diagonal());
  const std::uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                   [&](std::uint32_t a, std::uint32_t c) {
                     return spheres_[a].c[axis] < spheres_[c].c[axis];
                   });
  const std::uint32_t l = build(g, begin, mid, boxes, leaf_size);
  const std::uint32_t r = build(g, mid, end, boxes, leaf_size);
  nodes_[id].first = l;
  nodes_[id].right = r;
  return id;
}

SplitCount Bsh::count(const RoundingGuard& g, const TriangleSoup& soup, const PreparedPlane& plane,
                      BspMembership m, ExactStats& stats) const {
  SplitCount c;
  if (nodes_.empty()) return c;
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  std::vector<int> signs;
  while (top > 0) {
    const Node& nd = nodes_[stack[--top]];
    ++sphere_tests_;
    const int s = sphere_side(g, plane, nd.s);
    if (s != 0) {
      c.add(s < 0 ? Reach::Left : Reach::Right, nd.total);
      continue;
    }
    if (nd.count == 0) {
      stack[top++] = nd.first;
      stack[top++] = nd.right;
      continue;
    }
    for (std::uint32_t i = nd.first; i < nd.first + nd.count; ++i) {
      const std::uint32_t t = order_[i];
      ++sphere_tests_;
      const int ts = nd.count > 1 ? sphere_side(g, plane, spheres_[t]) : 0;
      if (ts != 0) {
        c.add(ts < 0 ? Reach::Left : Reach::Right);
        continue;
      }
      ++triangle_tests_;
      c.add(reach(polygon_signs(g, soup, plane, tris_[t], signs, stats), m));
    }
  }
  return c;
}

}  // namespace bsprt
