// validate_kd_coverage: an exact check of the kd build, independent of its
// double clipping (kd_clip.cpp). Polygons are clipped with rationals.
#include <algorithm>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <CGAL/Exact_rational.h>

#include "builder/kd/kd_build.h"

namespace bsprt {
namespace {

using Q = CGAL::Exact_rational;

struct QPoint {
  Q c[3];
};
using QPolygon = std::vector<QPoint>;

/// Keeps the part of `in` with x_k <= p (upper = false) or x_k >= p (upper = true),
/// closed half-space, exact. A non-empty result is a point, segment or polygon.
QPolygon clip(const QPolygon& in, int k, float p, bool upper) {
  QPolygon out;
  const Q plane(p);
  auto inside = [&](const QPoint& v) { return upper ? v.c[k] >= plane : v.c[k] <= plane; };
  for (std::size_t i = 0; i < in.size(); ++i) {
    const QPoint& a = in[i];
    const QPoint& b = in[(i + 1) % in.size()];
    const bool ia = inside(a), ib = inside(b);
    if (ia) out.push_back(a);
    if (ia != ib && a.c[k] != plane && b.c[k] != plane) {
      const Q t = (plane - a.c[k]) / (b.c[k] - a.c[k]);
      QPoint q;
      for (int j = 0; j < 3; ++j) q.c[j] = a.c[j] + t * (b.c[j] - a.c[j]);
      q.c[k] = plane;
      out.push_back(q);
    }
  }
  return out;
}

QPolygon clip_box(QPolygon p, const Box3f& cell) {
  for (int k = 0; k < 3 && !p.empty(); ++k) {
    p = clip(p, k, cell.lo[k], true);
    if (!p.empty()) p = clip(p, k, cell.hi[k], false);
  }
  return p;
}

struct Checker {
  const KdTree& tree;
  std::uint32_t tri;
  std::uint32_t failed_leaf = 0;

  /// True when every ray hitting `poly` (= triangle ∩ closed cell of `node`)
  /// finds the triangle in the subtree: it is listed in every leaf it touches,
  /// or on one side where it lies in a split plane.
  bool found(std::uint32_t node, const QPolygon& poly) {
    if (poly.empty()) return true;
    const KdNode& n = tree.nodes[node];
    if (n.is_leaf()) {
      const auto* b = tree.prims.data() + n.prim_offset();
      if (std::find(b, b + n.prim_count(), tri) != b + n.prim_count()) return true;
      failed_leaf = node;
      return false;
    }
    const int k = n.axis();
    const Q plane(n.split);
    bool below = false, above = false;
    for (const QPoint& v : poly) {
      below |= v.c[k] < plane;
      above |= v.c[k] > plane;
    }
    const QPolygon lo = clip(poly, k, n.split, false), hi = clip(poly, k, n.split, true);
    if (!below && !above) return found(node + 1, lo) || found(n.upper_child(), hi);  // in the plane
    return found(node + 1, lo) && found(n.upper_child(), hi);
  }
};

}  // namespace

void validate_kd_coverage(const KdTree& tree, const TriangleSoup& soup) {
  tree.validate();
  if (tree.triangle_count != soup.size()) {
    std::ostringstream s;
    s << "kd-tree built for " << tree.triangle_count << " triangles, scene has " << soup.size();
    throw std::logic_error(s.str());
  }
  for (std::uint32_t t = 0; t < soup.size(); ++t) {
    if (soup.is_degenerate(t)) continue;
    QPolygon poly;
    for (const Vec3f& v : soup.corners(t)) {
      if (!is_finite(v)) { poly.clear(); break; }
      poly.push_back({{Q(v.x), Q(v.y), Q(v.z)}});
    }
    if (poly.empty()) continue;
    // The leaves cover the root box only: a triangle reaching out of it would
    // be clipped below and its outside part never checked (nor ever hit).
    bool inside = true;
    for (const Vec3f& v : soup.corners(t))
      for (int a = 0; a < 3; ++a) inside = inside && tree.bounds.lo[a] <= v[a] && v[a] <= tree.bounds.hi[a];
    if (!inside) {
      std::ostringstream s;
      s << "kd-tree: triangle " << t << " sticks out of the root box (its points outside lie in no leaf)";
      throw std::logic_error(s.str());
    }
    Checker c{tree, t};
    if (!c.found(0, clip_box(poly, tree.bounds))) {
      std::ostringstream s;
      s << "kd-tree: triangle " << t << " touches the cell of leaf node " << c.failed_leaf
        << " but is not listed there";
      throw std::logic_error(s.str());
    }
  }
}

}  // namespace bsprt
