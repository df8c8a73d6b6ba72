// Traversal-based triangle intersection, measured (builder/bsp_face_hits.h):
// which face-plane splits prove hits, and which hits they prove.
#include <catch2/catch.hpp>
#include <cmath>

#include "bsp_test_util.h"
#include "builder/bsp/bsp_face_hits.h"
#include "geometry/io/load_mesh.h"
#include "robust/degenerate.h"
#include "test_util.h"

namespace bsprt {
namespace {

/// T0 inside the box, T1 spanning the box (0,0,0)-(4,4,1).
TriangleSoup two_triangles() {
  TriangleSoup s;
  s.vertices = {{1, 1, 0.5f}, {3, 1, 0.5f}, {1, 3, 0.5f}, {0, 0, 0}, {4, 4, 1}, {0, 4, 1}};
  s.triangles = {{0, 1, 2}, {3, 4, 5}};
  classify_degenerate(s);
  return s;
}

/// A hand-built tree: `nodes` in preorder, every leaf listing both triangles.
BspTree hand_tree(const TriangleSoup& s, std::vector<PlaneDef> planes, std::vector<BspNode> nodes) {
  std::vector<std::uint32_t> refs;
  for (BspNode& n : nodes)
    if (n.is_leaf()) {
      n.a = std::uint32_t(refs.size());
      n.b = 2;
      refs.insert(refs.end(), {0u, 1u});
    }
  BspTree t(s.bounds(), std::move(planes), std::move(nodes), std::move(refs), BspMembership::Closed, true);
  t.validate(s.size(), &s);
  return t;
}

BspNode inner(std::uint32_t plane, std::uint32_t left, std::uint32_t right) { return BspNode{plane, left, right}; }
BspNode leaf() { return BspNode{}; }

Hit hit_on(std::uint32_t prim, float u, float v) {
  Hit h;
  h.t = 1.0f;
  h.prim = prim;
  h.u = u;
  h.v = v;
  return h;
}

}  // namespace

TEST_CASE("face hits: a face split proves hits only where its cross-section lies inside the triangle", "[bsp][face]") {
  const TriangleSoup s = two_triangles();
  const std::vector<PlaneDef> planes = {PlaneDef::edge(0, 0), PlaneDef::edge(0, 1), PlaneDef::edge(0, 2),
                                        PlaneDef::face(0)};
  SECTION("the face plane cuts the whole box: its cross-section is larger than the triangle") {
    const BspTree t = hand_tree(s, {PlaneDef::face(0)}, {inner(0, 1, 2), leaf(), leaf()});
    const FaceHitLocator loc(t, s);
    CHECK(loc.stats().inner_nodes == 1);
    CHECK(loc.stats().face_nodes == 1);
    CHECK(loc.stats().proving_nodes == 0);
    CHECK(loc.proving_node(hit_on(0, 0.25f, 0.25f)) == FaceHitLocator::kNone);
  }
  SECTION("inside the three edge planes the cross-section is the triangle itself") {
    // Edge planes' normals point into the triangle: the right child is inside.
    const BspTree t = hand_tree(
        s, planes,
        {inner(0, 1, 2), leaf(), inner(1, 3, 4), leaf(), inner(2, 5, 6), leaf(), inner(3, 7, 8), leaf(), leaf()});
    const FaceHitLocator loc(t, s);
    CHECK(loc.stats().inner_nodes == 4);
    CHECK(loc.stats().face_nodes == 1);
    CHECK(loc.stats().proving_nodes == 1);
    CHECK(loc.proves(6));
    CHECK_FALSE(loc.proves(0));
    CHECK(loc.proving_node(hit_on(0, 0.25f, 0.25f)) == 6);
    CHECK(loc.proving_node(hit_on(0, 0.0f, 0.0f)) == 6);  // a corner of T0 lies on the cross-section
    CHECK(loc.proving_node(hit_on(1, 0.25f, 0.25f)) == FaceHitLocator::kNone);  // T1 has no face split
    CHECK(loc.proving_node(Hit{}) == FaceHitLocator::kNone);                    // a miss
  }
  SECTION("outside one edge plane the cross-section leaves the triangle") {
    const BspTree t = hand_tree(s, planes, {inner(0, 1, 4), inner(3, 2, 3), leaf(), leaf(), leaf()});
    const FaceHitLocator loc(t, s);
    CHECK(loc.stats().face_nodes == 1);
    CHECK(loc.stats().proving_nodes == 0);
    CHECK_FALSE(loc.proves(1));
  }
  SECTION("inside two edge planes only: part of the cross-section is outside the third edge") {
    const BspTree t =
        hand_tree(s, planes, {inner(0, 1, 2), leaf(), inner(1, 3, 4), leaf(), inner(3, 5, 6), leaf(), leaf()});
    const FaceHitLocator loc(t, s);
    CHECK(loc.stats().proving_nodes == 0);
  }
}

TEST_CASE(
    "face hits: on suzanne every proving split's cross-section is inside its triangle and proves perpendicular hits",
    "[bsp][face]") {
  const test::BspScene s = test::build_bsp_scene(load_mesh(test::scene_path("suzanne.obj")));
  const FaceHitLocator loc(s.exact, s.soup);
  const FaceProofStats& st = loc.stats();
  INFO("inner " << st.inner_nodes << " face " << st.face_nodes << " proving " << st.proving_nodes);
  CHECK(st.proving_nodes > 0);
  CHECK(st.proving_nodes <= st.face_nodes);
  CHECK(st.face_nodes <= st.inner_nodes);
  const BruteForceTracer brute(s.soup);
  const Box3f b = s.soup.bounds();
  const double size = double(length(b.hi - b.lo));
  std::size_t checked = 0, proven = 0;
  for (std::uint32_t i = 0; i < s.exact.nodes().size(); ++i) {
    if (s.exact.nodes()[i].is_leaf() || !loc.proves(i)) continue;
    const std::uint32_t tri = s.exact.plane_of(i).tri();
    // Independent of the exact decision: the cross-section's vertices (double
    // approximations) have non-negative barycentrics in the triangle.
    Cell left, right;
    {
      RoundingGuard g;
      ExactStats es;
      REQUIRE(s.exact.cell(s.soup, i).split(g, s.soup, prepare_plane(g, s.soup, s.exact.plane_of(i)), left, right, es));
    }
    const Vec3d a(s.soup.corner(tri, 0)), e1 = Vec3d(s.soup.corner(tri, 1)) - a, e2 = Vec3d(s.soup.corner(tri, 2)) - a;
    const Vec3d n = cross(e1, e2);
    Vec3d centroid(0, 0, 0);
    int on = 0;
    for (const CellVertex& v : left.vertices()) {
      if (!std::binary_search(v.facets.begin(), v.facets.end(), s.exact.plane_of(i))) continue;
      const Vec3d q = v.point.approx() - a;
      const double nn = dot(n, n);
      const double bu = dot(cross(q, e2), n) / nn, bv = dot(cross(e1, q), n) / nn;
      CHECK(bu >= -1e-9);
      CHECK(bv >= -1e-9);
      CHECK(bu + bv <= 1.0 + 1e-9);
      centroid += v.point.approx();
      ++on;
    }
    REQUIRE(on >= 3);
    centroid = centroid / double(on);
    // A ray down the normal onto the centroid: when its nearest hit is this
    // triangle, the locator finds a proving node for it.
    const Vec3d dir = n / length(n);
    Ray r;
    r.org = Vec3f(centroid + dir * (1e-3 * size));
    r.dir = Vec3f(-dir);
    const Hit h = brute.trace(r);
    if (h.prim != tri) continue;
    ++checked;
    const std::uint32_t p = loc.proving_node(h);
    proven += p != FaceHitLocator::kNone;
    CHECK(p != FaceHitLocator::kNone);
  }
  INFO("checked " << checked << " proven " << proven);
  CHECK(checked > st.proving_nodes / 2);
}

}  // namespace bsprt
