// The certified epsilon is a true bound (docs/certified-epsilons.md §2): at
// the exact vertices of every plane node's cell and at random exact points of
// the cell, |F(x) − s·value(x)| (float plane vs scaled exact plane, evaluated
// in exact rationals) is at most the stored delta <= eps; and the bound
// function is also right (and tight) for deliberately perturbed planes.
#include <catch2/catch.hpp>
#include <CGAL/Exact_rational.h>
#include <fmt/core.h>

#include <array>
#include <random>
#include <set>
#include <tuple>

#include "bsp_test_util.h"
#include "geometry/scenes/default_scene.h"
#include "geometry/io/load_mesh.h"
#include "test_util.h"

using namespace bsprt;
using namespace bsprt::test;

namespace {

using Q = CGAL::Exact_rational;
using QV = std::array<Q, 3>;

QV qv(const Vec3f& v) { return {Q(double(v.x)), Q(double(v.y)), Q(double(v.z))}; }
QV sub(const QV& a, const QV& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
QV cross(const QV& a, const QV& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Q dot(const QV& a, const QV& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// value(p) = n·(p − r), re-derived from plane.h's definitions (independent
/// of robust/).
void exact_plane(const TriangleSoup& soup, PlaneDef p, QV& n, QV& r) {
  if (p.is_kd()) {
    n = {Q(0), Q(0), Q(0)};
    n[p.axis()] = Q(1);
    r = n;
    r[p.axis()] = Q(double(p.coord()));
    return;
  }
  const std::uint32_t t = p.tri();
  const QV p0 = qv(soup.corner(t, 0)), p1 = qv(soup.corner(t, 1)), p2 = qv(soup.corner(t, 2));
  n = cross(sub(p1, p0), sub(p2, p0));
  r = p0;
  if (p.kind == PlaneKind::Edge) {
    const int k = p.edge_index();
    const QV a = qv(soup.corner(t, k)), b = qv(soup.corner(t, (k + 1) % 3));
    n = cross(n, sub(b, a));
    r = a;
  }
}

/// The point where three stored planes meet (Cramer's rule, exact).
QV exact_point(const TriangleSoup& soup, const std::array<PlaneDef, 3>& def) {
  QV n[3], r[3];
  Q rhs[3];
  for (int i = 0; i < 3; ++i) {
    exact_plane(soup, def[i], n[i], r[i]);
    rhs[i] = dot(n[i], r[i]);
  }
  const QV bc = cross(n[1], n[2]), ca = cross(n[2], n[0]), ab = cross(n[0], n[1]);
  const Q den = dot(n[0], bc);
  QV x;
  for (int i = 0; i < 3; ++i) x[i] = (rhs[0] * bc[i] + rhs[1] * ca[i] + rhs[2] * ab[i]) / den;
  return x;
}

/// |F(x) − s·value(x)| exactly.
Q exact_error(const FloatPlane& f, const QV& n, const QV& r, const QV& x) {
  const Q fx = Q(double(f.n[0])) * x[0] + Q(double(f.n[1])) * x[1] + Q(double(f.n[2])) * x[2] +
               Q(double(f.d));
  const Q gx = Q(f.scale) * dot(n, sub(x, r));
  const Q e = fx - gx;
  return e < 0 ? -e : e;
}

struct EpsStats {
  std::size_t nodes = 0, points = 0, violations = 0, loose = 0;
  double max_ratio = 0.0;  ///< max exact error / delta
};

/// Checks one plane node: vertices and random convex combinations.
void check_node(const TriangleSoup& soup, PlaneDef def, const Cell& cell, std::mt19937& rng,
                const std::set<std::tuple<float, float, float, float, float>>& stored, EpsStats& st) {
  const FloatPlane f = flat_plane_of(soup, def, cell);
  if (!stored.count({f.n[0], f.n[1], f.n[2], f.d, f.eps})) return;  // became a kd node
  ++st.nodes;
  QV n, r;
  exact_plane(soup, def, n, r);
  std::vector<QV> verts;
  for (const CellVertex& v : cell.vertices()) verts.push_back(exact_point(soup, v.point.def));
  std::vector<QV> pts = verts;
  std::uniform_int_distribution<int> w(0, 1000);
  for (int k = 0; k < 8; ++k) {
    QV p{Q(0), Q(0), Q(0)};
    Q total(0);
    for (const QV& v : verts) {
      const Q wi(w(rng));
      total += wi;
      for (int i = 0; i < 3; ++i) p[i] += wi * v[i];
    }
    if (total == 0) continue;
    for (int i = 0; i < 3; ++i) p[i] /= total;
    pts.push_back(p);
  }
  for (const QV& x : pts) {
    ++st.points;
    const Q e = exact_error(f, n, r, x);
    if (e > Q(f.delta) || e > Q(double(f.eps))) ++st.violations;
    if (f.delta > 0) st.max_ratio = std::max(st.max_ratio, CGAL::to_double(e) / f.delta);
  }
}

EpsStats check_scene_eps(TriangleSoup soup) {
  const BspScene s = build_bsp_scene(std::move(soup));
  std::set<std::tuple<float, float, float, float, float>> stored;
  for (std::size_t i = 0; i < s.flat.nodes.size(); ++i) {  // tails follow their heads
    const FlatBspNode& n = s.flat.nodes[i];
    if (!n.is_plane()) continue;
    const FlatBspNode& tail = s.flat.nodes[++i];
    stored.insert({n.normal(0), n.normal(1), n.normal(2), tail.tail_d(), tail.tail_eps()});
  }
  EpsStats st;
  std::mt19937 rng(17);
  s.exact.for_each_cell(s.soup, [&](std::uint32_t i, const Cell& cell) {
    if (s.exact.nodes()[i].is_leaf() || s.exact.plane_of(i).is_kd()) return;
    check_node(s.soup, s.exact.plane_of(i), cell, rng, stored, st);
  });
  CHECK(st.nodes >= stored.size());
  return st;
}

}  // namespace

TEST_CASE("certified epsilon bounds the float plane over exact cells", "[bsp][epsilon]") {
  const TriangleSoup sphere = make_icosphere({0, 0, 0}, 1.0f, 2);
  const std::vector<std::pair<std::string, TriangleSoup>> scenes = {
      {"suzanne", load_mesh(scene_path("suzanne.obj"))},
      {"icosphere", sphere},
      {"torus knot", make_torus_knot({0, 0, 0}, 1.0f, 0.3f, 2, 3, 64, 8)},
      {"icosphere + 1e5", [&] { TriangleSoup t = sphere; for (Vec3f& v : t.vertices) v += {1e5f, 0, -1e5f}; return t; }()},
      {"icosphere * 1e-4", [&] { TriangleSoup t = sphere; for (Vec3f& v : t.vertices) v *= 1e-4f; return t; }()},
  };
  for (const auto& [name, soup] : scenes) {
    const EpsStats st = check_scene_eps(soup);
    fmt::print("epsilon {:18} plane nodes {:5} points {:6} max error/delta {:.3f}\n", name, st.nodes,
               st.points, st.max_ratio);
    INFO(name << ": " << st.violations << " violations in " << st.points << " points");
    CHECK(st.violations == 0);
    CHECK(st.nodes > 0);
  }
}

TEST_CASE("plane_rounding_bound is a true and tight bound for perturbed planes", "[bsp][epsilon]") {
  const BspScene s = build_bsp_scene(load_mesh(scene_path("suzanne.obj")));
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> ulps(-40, 40);
  std::size_t checked = 0, violations = 0, loose = 0;
  s.exact.for_each_cell(s.soup, [&](std::uint32_t i, const Cell& cell) {
    if (s.exact.nodes()[i].is_leaf() || s.exact.plane_of(i).is_kd() || checked >= 150) return;
    const PlaneDef def = s.exact.plane_of(i);
    FloatPlane f = flat_plane_of(s.soup, def, cell);
    for (float& c : f.n) c = c + float(ulps(rng)) * 0x1p-24f;  // perturbed on purpose
    f.d += float(ulps(rng)) * 1e-3f;
    std::vector<IntervalBox> boxes;
    for (const CellVertex& v : cell.vertices()) boxes.push_back(v.point.box);
    {
      RoundingGuard g;
      const PreparedPlane pp = prepare_plane(g, s.soup, def);
      f.delta = plane_rounding_bound(g, pp, f.scale, f.n, f.d, boxes);
    }
    QV n, r;
    exact_plane(s.soup, def, n, r);
    double worst = 0.0;
    for (const CellVertex& v : cell.vertices()) {
      const Q e = exact_error(f, n, r, exact_point(s.soup, v.point.def));
      violations += e > Q(f.delta);
      worst = std::max(worst, CGAL::to_double(e));
    }
    loose += worst < 0.5 * f.delta;  // the max over vertices is the true max: bound should be near it
    ++checked;
  });
  CHECK(checked > 20);
  CHECK(violations == 0);
  CHECK(loose == 0);
}
