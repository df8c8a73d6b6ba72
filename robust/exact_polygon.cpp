/// \file exact_polygon.cpp
/// Exact Sutherland–Hodgman clipping of a triangle's polygon T ∩ C by a stored
/// plane, with corner-sign shortcuts (exact_polygon.h).
#include "robust/exact_polygon.h"

#include <algorithm>

namespace bsprt {

namespace {

PolyLoc loc_on_edge_plane(PlaneDef e, std::uint32_t t) {
  if (e.kind == PlaneKind::Edge && e.tri() == t) return PolyLoc(int(PolyLoc::Edge0) + e.edge_index());
  return PolyLoc::Inside;
}

/// Sign of a vertex from its location and T's corner signs; 2 when unknown.
int sign_from_corners(PolyLoc loc, const int cs[3]) {
  const int l = int(loc);
  if (l <= 2) return cs[l];
  if (l <= 5) {
    const int a = cs[l - 3], b = cs[(l - 2) % 3];
    if (a == b) return a;
    if (a == 0) return b;
    if (b == 0) return a;
  }
  return 2;
}

PolyVertex crossing(const RoundingGuard& g, const TriangleSoup& soup, std::uint32_t t,
                    PlaneDef edge_plane, PlaneDef split, ExactStats& stats) {
  PolyVertex x;
  x.point = make_point(g, soup, PlaneDef::face(t), edge_plane, split, stats);
  x.loc = loc_on_edge_plane(edge_plane, t);
  return x;
}

}  // namespace

Box3d ClippedTriangle::bounds() const {
  Box3d b;
  for (const PolyVertex& v : verts) {
    b.extend(Vec3d(v.point.box.lo[0], v.point.box.lo[1], v.point.box.lo[2]));
    b.extend(Vec3d(v.point.box.hi[0], v.point.box.hi[1], v.point.box.hi[2]));
  }
  return b;
}

ClippedTriangle full_triangle(const TriangleSoup& soup, std::uint32_t t) {
  ClippedTriangle c;
  c.tri = t;
  c.verts.resize(3);
  for (int k = 0; k < 3; ++k) {
    c.verts[k].point = corner_point(soup, t, k);
    c.verts[k].next = PlaneDef::edge(t, k);
    c.verts[k].loc = PolyLoc(k);
  }
  return c;
}

SideSummary polygon_signs(const RoundingGuard& g, const TriangleSoup& soup,
                          const PreparedPlane& plane, const ClippedTriangle& c,
                          std::vector<int>& signs, ExactStats& stats) {
  int cs[3];
  for (int k = 0; k < 3; ++k) cs[k] = side(g, soup, plane, corner_point(soup, c.tri, k), stats);
  const std::size_t n = c.verts.size();
  signs.resize(n);
  const bool uniform = cs[0] == cs[1] && cs[1] == cs[2];
  SideSummary s;
  for (std::size_t i = 0; i < n; ++i) {
    int v = uniform ? cs[0] : sign_from_corners(c.verts[i].loc, cs);
    if (v == 2) v = side(g, soup, plane, c.verts[i].point, stats);
    signs[i] = v;
    s.neg |= v < 0;
    s.zero |= v == 0;
    s.pos |= v > 0;
  }
  return s;
}

ClippedTriangle clip_polygon(const RoundingGuard& g, const TriangleSoup& soup,
                             const PreparedPlane& plane, const ClippedTriangle& c,
                             const std::vector<int>& signs, int keep_side, ExactStats& stats) {
  ClippedTriangle out;
  out.tri = c.tri;
  const std::size_t n = c.verts.size();
  // s(i) ≤ 0 means "kept"; flipping the signs keeps the other side.
  auto s = [&](std::size_t i) { return keep_side < 0 ? signs[i] : -signs[i]; };
  if (n == 1) {
    if (s(0) <= 0) out.verts.push_back(c.verts[0]);
    return out;
  }
  if (n == 2) {
    const PlaneDef line = c.verts[0].next;
    if (s(0) <= 0) out.verts.push_back(c.verts[0]);
    if ((s(0) < 0 && s(1) > 0) || (s(0) > 0 && s(1) < 0))
      out.verts.push_back(crossing(g, soup, c.tri, line, plane.def, stats));
    if (s(1) <= 0) out.verts.push_back(c.verts[1]);
    for (PolyVertex& v : out.verts) v.next = line;
    return out;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    const int si = s(i), sj = s(j);
    const PlaneDef e = c.verts[i].next;
    if (si <= 0) {
      PolyVertex v = c.verts[i];
      v.next = (si == 0 && sj > 0) ? plane.def : e;
      out.verts.push_back(v);
    }
    if ((si < 0 && sj > 0) || (si > 0 && sj < 0)) {
      PolyVertex x = crossing(g, soup, c.tri, e, plane.def, stats);
      x.next = si < 0 ? plane.def : e;  // exit: along the split plane; entry: along e
      out.verts.push_back(x);
    }
  }
  if (out.verts.size() == 2) out.verts[1].next = out.verts[0].next;
  return out;
}

}  // namespace bsprt
