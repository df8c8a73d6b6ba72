/// \file bsp_candidates.cpp
/// kd sweeps and BSP candidate counting with the SAH (bsp_candidates.h).
#include "builder/bsp/bsp_candidates.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bsprt {

namespace {

constexpr double kMinAreaFraction = 1e-9;  // a child thinner than this cannot pay off

float float_down(double x) {
  float f = static_cast<float>(x);
  if (double(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}
float float_up(double x) {
  float f = static_cast<float>(x);
  if (double(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

/// One side of the slab around an axis-planar triangle at c (BspConfig::
/// planar_slabs): one float step from c, or 2^-60 when |c| < 2^-60, so that no
/// split lies at a subnormal position (the kd-tree builder skips its offset
/// planes there for the same reason: a watertight test's products underflow).
float slab_side(float c, int dir) {
  constexpr float kInf = std::numeric_limits<float>::infinity(), kNear0 = 0x1p-60f;
  if (std::abs(c) < kNear0) return dir < 0 ? c - kNear0 : c + kNear0;
  return std::nextafter(c, dir < 0 ? -kInf : kInf);
}

double box_area(const Box3d& b) {
  const Vec3d d = b.diagonal();
  return 2 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

std::size_t count_le(const std::vector<double>& v, double s) {
  return std::upper_bound(v.begin(), v.end(), s) - v.begin();
}
std::size_t count_lt(const std::vector<double>& v, double s) {
  return std::lower_bound(v.begin(), v.end(), s) - v.begin();
}

/// Counts of a kd plane at s on one axis from sorted bounds (steering counts).
SplitCount kd_count(const std::vector<double>& lo, const std::vector<double>& hi,
                    const std::vector<double>& flat, double s, BspMembership m) {
  const std::size_t n = lo.size();
  const std::size_t nf = count_le(flat, s) - count_lt(flat, s);
  const bool closed = m == BspMembership::Closed;
  const std::size_t l = (closed ? count_le(lo, s) : count_lt(lo, s)) - nf;
  const std::size_t r = n - (closed ? count_lt(hi, s) : count_le(hi, s)) - nf;
  SplitCount c;
  c.coplanar = nf;
  c.both = l + r > n - nf ? l + r - (n - nf) : 0;
  c.left = l - c.both;
  c.right = r - c.both;
  return c;
}

void kd_axis(const NodeView& v, const BspConfig& cfg, int a, const std::vector<Box3d>& tb,
             std::vector<Candidate>& out) {
  const std::size_t n = v.tris.size();
  std::vector<double> lo(n), hi(n), flat, cand;
  cand.reserve(2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    lo[i] = tb[i].lo[a];
    hi[i] = tb[i].hi[a];
    if (lo[i] == hi[i]) {
      flat.push_back(lo[i]);
      if (cfg.planar_slabs) {  // a slab around it (BspConfig::planar_slabs)
        const float c = float_down(lo[i]);
        cand.push_back(slab_side(c, -1));
        cand.push_back(slab_side(c, +1));
      }
    }
    cand.push_back(float_down(lo[i]));
    cand.push_back(float_up(hi[i]));
  }
  std::sort(lo.begin(), lo.end());
  std::sort(hi.begin(), hi.end());
  std::sort(flat.begin(), flat.end());
  std::sort(cand.begin(), cand.end());
  cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
  const double cl = v.bounds.lo[a], ch = v.bounds.hi[a];
  for (double s : cand) {
    if (!(s > cl && s < ch)) continue;
    const PlaneDef p = PlaneDef::kd(a, static_cast<float>(s));
    double al, ar;
    if (v.box) {
      Box3d l = v.bounds, r = v.bounds;
      l.hi[a] = s;
      r.lo[a] = s;
      al = box_area(l);
      ar = box_area(r);
    } else {
      ApproxPlane ap;
      ap.n = Vec3d(0, 0, 0);
      ap.n[a] = 1;
      ap.d = -s;
      split_areas(v.loops, ap, al, ar);
    }
    if (al <= kMinAreaFraction * v.area || ar <= kMinAreaFraction * v.area) continue;
    const SplitCount c = kd_count(lo, hi, flat, s, cfg.membership);
    out.push_back({p, sah_cost(cfg, cfg.c_kd, c, al, ar, v.area), al, ar, cfg.c_kd, keeps_all(c, v.tris.size())});
  }
}

/// Face/edge planes of the node's triangles, without (approximate) duplicates.
std::vector<PlaneDef> bsp_planes(const TriangleSoup& soup, const NodeView& v, const BspConfig& cfg) {
  std::vector<std::pair<ApproxPlane, PlaneDef>> all;
  for (const ClippedTriangle& c : v.tris) {
    if (cfg.face_candidates) all.emplace_back(ApproxPlane{}, PlaneDef::face(c.tri));
    if (cfg.edge_candidates)
      for (int k = 0; k < 3; ++k) all.emplace_back(ApproxPlane{}, PlaneDef::edge(c.tri, k));
  }
  for (auto& [ap, p] : all) {
    ap = approx_plane(soup, p);
    const int m = max_axis(ap.n);
    if (ap.n[m] < 0) {
      ap.n = -ap.n;
      ap.d = -ap.d;
    }
  }
  auto key = [](const ApproxPlane& a) { return std::array<double, 4>{a.n.x, a.n.y, a.n.z, a.d}; };
  std::sort(all.begin(), all.end(), [&](const auto& x, const auto& y) { return key(x.first) < key(y.first); });
  std::vector<PlaneDef> planes;
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (i > 0) {
      const auto a = key(all[i].first), b = key(all[i - 1].first);
      const double tol = 1e-12 * (1 + std::abs(a[3]));
      if (std::abs(a[0] - b[0]) <= 1e-12 && std::abs(a[1] - b[1]) <= 1e-12 &&
          std::abs(a[2] - b[2]) <= 1e-12 && std::abs(a[3] - b[3]) <= tol)
        continue;
    }
    planes.push_back(all[i].second);
  }
  return planes;
}

}  // namespace

NodeView make_node_view(const TriangleSoup& soup, const Cell& cell,
                        const std::vector<ClippedTriangle>& tris) {
  NodeView v{cell, tris, cell.facet_loops(soup), cell.bounds(), 0.0, cell.is_box()};
  v.area = v.box ? box_area(v.bounds) : loops_area(v.loops);
  return v;
}

double sah_cost(const BspConfig& cfg, double c_trav, const SplitCount& n, double area_left,
                double area_right, double area, bool* coplanar_left) {
  const double pl = std::clamp(area_left / area, 0.0, 1.0);
  const double pr = std::clamp(area_right / area, 0.0, 1.0);
  const double nl = double(n.left + n.both), nr = double(n.right + n.both), nc = double(n.coplanar);
  // Wald-Havran's bonus for cutting off empty space (kd_build's 0.8): the cost
  // times empty_bonus when one child lists no triangle.
  const auto bonus = [&](double cost, double left, double right) {
    return (left == 0.0 || right == 0.0) ? cost * cfg.empty_bonus : cost;
  };
  if (cfg.coplanar_to_both || n.coplanar == 0) {
    if (coplanar_left) *coplanar_left = true;
    return bonus(c_trav + cfg.c_isect * (pl * (nl + nc) + pr * (nr + nc)), nl + nc, nr + nc);
  }
  const double cl = bonus(c_trav + cfg.c_isect * (pl * (nl + nc) + pr * nr), nl + nc, nr);
  const double cr = bonus(c_trav + cfg.c_isect * (pl * nl + pr * (nr + nc)), nl, nr + nc);
  if (coplanar_left) *coplanar_left = cl <= cr;
  return std::min(cl, cr);
}

double bsp_traversal_cost(const BspConfig& cfg, std::size_t n, bool kd_exists) {
  return kd_exists ? cfg.c_bsp_slope * cfg.c_isect * (double(n) - 2.0) + cfg.c_kd : cfg.c_bsp_fixed;
}

std::size_t add_kd_candidates(const NodeView& v, const BspConfig& cfg, std::vector<Candidate>& out) {
  const std::size_t before = out.size();
  if (!cfg.kd_candidates || v.tris.empty()) return 0;
  std::vector<Box3d> tb(v.tris.size());
  for (std::size_t i = 0; i < v.tris.size(); ++i) tb[i] = v.tris[i].bounds();
  for (int a = 0; a < 3; ++a) kd_axis(v, cfg, a, tb, out);
  return out.size() - before;
}

void add_bsp_candidates(const RoundingGuard& g, const TriangleSoup& soup, const NodeView& v,
                        const BspConfig& cfg, bool kd_exists, std::vector<Candidate>& out,
                        ExactStats& stats) {
  const std::vector<PlaneDef> planes = bsp_planes(soup, v, cfg);
  if (planes.empty()) return;
  const std::size_t n = v.tris.size();
  const Bsh bsh(g, v.tris, n >= cfg.bsh_min_triangles ? 4 : n);
  const double c_trav = bsp_traversal_cost(cfg, n, kd_exists);
  for (PlaneDef p : planes) {
    const PreparedPlane pp = prepare_plane(g, soup, p);
    double al, ar;
    split_areas(v.loops, pp.approx, al, ar);
    if (al <= kMinAreaFraction * v.area || ar <= kMinAreaFraction * v.area) continue;
    // A lower bound first: every triangle costs at least min(P_L, P_R).
    const double lower = c_trav + cfg.c_isect * double(n) * std::min(al, ar) / v.area;
    if (lower >= cfg.c_isect * double(n)) continue;
    const SplitCount c = bsh.count(g, soup, pp, cfg.membership, stats);
    out.push_back({p, sah_cost(cfg, c_trav, c, al, ar, v.area), al, ar, c_trav, keeps_all(c, n)});
  }
}

}  // namespace bsprt
