/// \file cell.cpp
/// Exact combinatorial splitting of convex cells and their approximate areas.
#include "robust/cell.h"

#include <algorithm>
#include <cmath>

#include "geometry/core/check.h"

namespace bsprt {

namespace {

void insert_sorted(std::vector<PlaneDef>& v, PlaneDef p) {
  auto it = std::lower_bound(v.begin(), v.end(), p);
  if (it == v.end() || *it != p) v.insert(it, p);
}

/// Common planes of two sorted lists (at most `cap` reported).
int common_planes(const std::vector<PlaneDef>& a, const std::vector<PlaneDef>& b,
                  std::array<PlaneDef, 3>& out) {
  int n = 0;
  auto i = a.begin(), j = b.begin();
  while (i != a.end() && j != b.end()) {
    if (*i < *j) ++i;
    else if (*j < *i) ++j;
    else {
      if (n < 3) out[n] = *i;
      ++n;
      ++i;
      ++j;
    }
  }
  return n;
}

/// Keeps the facets of `old` that still carry ≥ 3 vertices of `c`, plus `p`, and
/// restricts each vertex's facet list to them.
void finish_child(std::vector<CellVertex>& verts, const std::vector<PlaneDef>& old, PlaneDef p,
                  std::vector<PlaneDef>& facets) {
  facets.clear();
  for (PlaneDef f : old) {
    int n = 0;
    for (const CellVertex& v : verts)
      if (std::binary_search(v.facets.begin(), v.facets.end(), f) && ++n >= 3) break;
    if (n >= 3) facets.push_back(f);
  }
  insert_sorted(facets, p);
  for (CellVertex& v : verts) {
    std::erase_if(v.facets, [&](PlaneDef f) { return !std::binary_search(facets.begin(), facets.end(), f); });
  }
}

Vec3d loop_vector_area(const std::vector<Vec3d>& pts) {
  Vec3d a(0, 0, 0);
  if (pts.size() < 3) return a;
  const Vec3d o = pts[0];
  for (std::size_t i = 1; i + 1 < pts.size(); ++i) a += cross(pts[i] - o, pts[i + 1] - o);
  return a * 0.5;
}

}  // namespace

Cell Cell::box(const Box3f& b) {
  Cell c;
  const PlaneDef lo[3] = {PlaneDef::kd(0, b.lo.x), PlaneDef::kd(1, b.lo.y), PlaneDef::kd(2, b.lo.z)};
  const PlaneDef hi[3] = {PlaneDef::kd(0, b.hi.x), PlaneDef::kd(1, b.hi.y), PlaneDef::kd(2, b.hi.z)};
  for (int m = 0; m < 8; ++m) {
    CellVertex v;
    for (int a = 0; a < 3; ++a) {
      const PlaneDef p = (m >> a) & 1 ? hi[a] : lo[a];
      v.point.def[a] = p;
      v.point.box.lo[a] = v.point.box.hi[a] = double(p.coord());
      v.facets.push_back(p);
    }
    std::sort(v.facets.begin(), v.facets.end());
    c.vertices_.push_back(std::move(v));
  }
  for (int a = 0; a < 3; ++a) {
    c.facets_.push_back(lo[a]);
    c.facets_.push_back(hi[a]);
  }
  std::sort(c.facets_.begin(), c.facets_.end());
  return c;
}

bool Cell::is_box() const {
  return std::all_of(facets_.begin(), facets_.end(), [](PlaneDef p) { return p.is_kd(); });
}

Box3d Cell::bounds() const {
  Box3d b;
  for (const CellVertex& v : vertices_) {
    b.extend(Vec3d(v.point.box.lo[0], v.point.box.lo[1], v.point.box.lo[2]));
    b.extend(Vec3d(v.point.box.hi[0], v.point.box.hi[1], v.point.box.hi[2]));
  }
  return b;
}

bool Cell::split(const RoundingGuard& g, const TriangleSoup& soup, const PreparedPlane& plane,
                 Cell& left, Cell& right, ExactStats& stats) const {
  const std::size_t n = vertices_.size();
  std::vector<int> s(n);
  bool neg = false, pos = false;
  for (std::size_t i = 0; i < n; ++i) {
    s[i] = side(g, soup, plane, vertices_[i].point, stats);
    neg |= s[i] < 0;
    pos |= s[i] > 0;
  }
  if (!neg || !pos) return false;
  const PlaneDef p = plane.def;
  std::vector<CellVertex> lv, rv;
  for (std::size_t i = 0; i < n; ++i) {
    CellVertex v = vertices_[i];
    if (s[i] == 0) insert_sorted(v.facets, p);
    if (s[i] <= 0) lv.push_back(v);
    if (s[i] >= 0) rv.push_back(std::move(v));
  }
  std::array<PlaneDef, 3> common;
  for (std::size_t i = 0; i < n; ++i) {
    if (s[i] >= 0) continue;
    for (std::size_t j = 0; j < n; ++j) {
      if (s[j] <= 0) continue;
      const int k = common_planes(vertices_[i].facets, vertices_[j].facets, common);
      if (k < 2) continue;
      BSPRT_CHECK_EQ(k, 2);  // an edge lies on exactly two facets
      CellVertex w;
      w.point = make_point(g, soup, common[0], common[1], p, stats);
      w.facets = {common[0], common[1]};
      insert_sorted(w.facets, p);
      lv.push_back(w);
      rv.push_back(std::move(w));
    }
  }
  finish_child(lv, facets_, p, left.facets_);
  finish_child(rv, facets_, p, right.facets_);
  left.vertices_ = std::move(lv);
  right.vertices_ = std::move(rv);
  return true;
}

std::vector<FacetLoop> Cell::facet_loops(const TriangleSoup& soup) const {
  Vec3d centroid(0, 0, 0);
  for (const CellVertex& v : vertices_) centroid += v.point.approx();
  centroid = centroid / double(std::max<std::size_t>(1, vertices_.size()));
  std::vector<FacetLoop> loops;
  loops.reserve(facets_.size());
  for (PlaneDef f : facets_) {
    FacetLoop L;
    L.plane = f;
    const ApproxPlane ap = approx_plane(soup, f);
    const Vec3d out = ap.eval(centroid) > 0 ? -ap.n : ap.n;  // the cell lies opposite `out`
    Vec3d c(0, 0, 0);
    for (const CellVertex& v : vertices_)
      if (std::binary_search(v.facets.begin(), v.facets.end(), f)) {
        L.pts.push_back(v.point.approx());
        c += L.pts.back();
      }
    c = c / double(std::max<std::size_t>(1, L.pts.size()));
    const Vec3d u0 = std::abs(out.x) < 0.6 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0);
    const Vec3d u = normalize(cross(out, u0)), w = cross(out, u);
    std::vector<std::pair<double, Vec3d>> ang;
    for (const Vec3d& q : L.pts) ang.emplace_back(std::atan2(dot(q - c, w), dot(q - c, u)), q);
    std::sort(ang.begin(), ang.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t i = 0; i < ang.size(); ++i) L.pts[i] = ang[i].second;
    L.vec_area = loop_vector_area(L.pts);
    loops.push_back(std::move(L));
  }
  return loops;
}

double loops_area(const std::vector<FacetLoop>& loops) {
  double a = 0;
  for (const FacetLoop& L : loops) a += length(L.vec_area);
  return a;
}

double Cell::area(const TriangleSoup& soup) const { return loops_area(facet_loops(soup)); }

double Cell::volume(const TriangleSoup& soup) const {
  const auto loops = facet_loops(soup);
  if (loops.empty() || loops[0].pts.empty()) return 0;
  const Vec3d o = loops[0].pts[0];
  double v = 0;
  for (const FacetLoop& L : loops)
    if (!L.pts.empty()) v += dot(L.pts[0] - o, L.vec_area);
  return v / 3.0;
}

void split_areas(const std::vector<FacetLoop>& loops, const ApproxPlane& p, double& left,
                 double& right) {
  left = right = 0;
  Vec3d sum_left(0, 0, 0);
  std::vector<Vec3d> lp, rp;
  for (const FacetLoop& L : loops) {
    const std::size_t n = L.pts.size();
    lp.clear();
    rp.clear();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3d& a = L.pts[i];
      const Vec3d& b = L.pts[(i + 1) % n];
      const double fa = p.eval(a), fb = p.eval(b);
      if (fa <= 0) lp.push_back(a);
      if (fa >= 0) rp.push_back(a);
      if ((fa < 0 && fb > 0) || (fa > 0 && fb < 0)) {
        const Vec3d x = a + (b - a) * (fa / (fa - fb));
        lp.push_back(x);
        rp.push_back(x);
      }
    }
    const Vec3d al = loop_vector_area(lp), ar = loop_vector_area(rp);
    sum_left += al;
    left += length(al);
    right += length(ar);
  }
  const double cross_section = length(sum_left);
  left += cross_section;
  right += cross_section;
}

}  // namespace bsprt
