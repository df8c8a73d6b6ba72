/// \file test_inside.cpp
/// Crossings with simulation of simplicity (CertifiedIntersector::crossings)
/// and the inside query (robust/inside_query.h): parity of rays exactly
/// through vertices and edges of closed meshes, and inside/outside/surface
/// against CGAL's Side_of_triangle_mesh.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <catch2/catch.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "geometry/io/load_mesh.h"
#include "geometry/scenes/default_scene.h"
#include "geometry/scenes/stiff_scenes.h"
#include "robust/certified_intersector.h"
#include "robust/degenerate.h"
#include "robust/inside_query.h"
#include "bsprt/io.h"
#include "test_util.h"

namespace bsprt {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<K::Point_3>;

Mesh cgal_mesh(const TriangleSoup& s) {
  Mesh m;
  std::vector<Mesh::Vertex_index> v;
  for (const Vec3f& p : s.vertices) v.push_back(m.add_vertex(K::Point_3(p.x, p.y, p.z)));
  for (const auto& t : s.triangles) m.add_face(v[t[0]], v[t[1]], v[t[2]]);
  return m;
}

PointSide cgal_side(const CGAL::Side_of_triangle_mesh<Mesh, K>& inside, const Vec3f& p) {
  const CGAL::Bounded_side b = inside(K::Point_3(p.x, p.y, p.z));
  return b == CGAL::ON_BOUNDED_SIDE ? PointSide::Inside
                                    : (b == CGAL::ON_BOUNDARY ? PointSide::OnSurface : PointSide::Outside);
}

/// Whether a - b is exact in float arithmetic, so that b + (a - b) is a.
bool exact_float_difference(const Vec3f& a, const Vec3f& b) {
  const Vec3f d = a - b;
  return double(b.x) + double(d.x) == double(a.x) && double(b.y) + double(d.y) == double(a.y) &&
         double(b.z) + double(d.z) == double(a.z);
}

std::size_t parity_rays() {
  const char* env = std::getenv("BSPRT_PARITY_RAYS");
  return env ? std::size_t(std::strtod(env, nullptr)) : 20000;
}

struct ClosedMesh {
  std::string name;
  TriangleSoup soup;
  bool convex;
};

std::vector<ClosedMesh> closed_meshes() {
  std::vector<ClosedMesh> m;
  m.push_back({"icosphere", make_icosphere({0.1f, -0.2f, 0.3f}, 1.0f, 2), true});
  m.push_back({"torus", make_torus({0.0f, 0.25f, 0.0f}, 1.0f, 0.35f, 24, 12), false});
  m.push_back({"cube", load_mesh(test::scene_path("cube.obj")), true});
  for (ClosedMesh& c : m) classify_degenerate(c.soup);
  return m;
}

}  // namespace

TEST_CASE("crossings: rays exactly through vertices and edges cross each sheet of a closed mesh once",
          "[exact][inside]") {
  for (const ClosedMesh& mesh : closed_meshes()) {
    INFO(mesh.name);
    REQUIRE(open_or_inconsistent_edges(mesh.soup) == 0);
    const CertifiedIntersector cert(mesh.soup);
    std::vector<std::uint32_t> all(mesh.soup.size());
    for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-3.0f, 3.0f);
    std::uniform_int_distribution<std::size_t> pick_v(0, mesh.soup.vertices.size() - 1);
    std::uniform_int_distribution<std::size_t> pick_t(0, mesh.soup.size() - 1);
    const std::size_t n = parity_rays() / 3;
    std::size_t exact_rays = 0, crossing_rays = 0;
    RayCounters counters;
    std::vector<CertifiedIntersector::Crossing> xs;
    for (std::size_t i = 0; i < n; ++i) {
      // Aim at a vertex, or at the midpoint of an edge; keep only rays whose
      // direction is exact, so the line passes exactly through the target.
      Vec3f target = mesh.soup.vertices[pick_v(rng)];
      if (i % 2) {
        const auto& t = mesh.soup.triangles[pick_t(rng)];
        target = (mesh.soup.vertices[t[0]] + mesh.soup.vertices[t[1]]) * 0.5f;
      }
      const Vec3f o{u(rng), u(rng), u(rng)};
      if (!exact_float_difference(target, o)) continue;
      ++exact_rays;
      Ray r;
      r.org = o;
      r.dir = target - o;
      r.tnear = -std::numeric_limits<float>::infinity();  // the whole line
      xs.clear();
      cert.crossings(r, all, xs, &counters);
      // A closed surface: the line enters as often as it leaves, alternating.
      REQUIRE(xs.size() % 2 == 0);
      std::sort(xs.begin(), xs.end(), [](const auto& a, const auto& b) { return a.t < b.t || (a.t == b.t && a.prim < b.prim); });
      int sum = 0;
      for (const auto& x : xs) sum += x.side;
      REQUIRE(sum == 0);
      if (mesh.convex) REQUIRE(xs.size() <= 2);
      crossing_rays += !xs.empty();
    }
    CHECK(exact_rays > n / 20);
    CHECK(crossing_rays > exact_rays / 4);
    // Exact zeros met: rule (a) and simulation of simplicity decide them
    // with exact signs of float products (exact_sum.h), not the exact stage.
    CHECK(counters.rule_decisions > 0);
  }
}

TEST_CASE("inside: equals CGAL's Side_of_triangle_mesh on random points, vertices, edges and faces",
          "[exact][inside]") {
  std::size_t total = 0, surface = 0, inside_count = 0;
  for (const ClosedMesh& mesh : closed_meshes()) {
    INFO(mesh.name);
    const Mesh m = cgal_mesh(mesh.soup);
    const CGAL::Side_of_triangle_mesh<Mesh, K> reference(m);
    const InsideQuery query(mesh.soup);
    std::vector<Vec3f> points;
    const Box3f b = mesh.soup.bounds();
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> u(-0.2f, 1.2f);
    for (int i = 0; i < 33000; ++i) {
      const Vec3f t{u(rng), u(rng), u(rng)};
      points.push_back({b.lo.x + (b.hi.x - b.lo.x) * t.x, b.lo.y + (b.hi.y - b.lo.y) * t.y,
                        b.lo.z + (b.hi.z - b.lo.z) * t.z});
    }
    for (const Vec3f& v : mesh.soup.vertices) points.push_back(v);  // on the surface
    for (const auto& t : mesh.soup.triangles) {
      const Vec3f a = mesh.soup.vertices[t[0]], c = mesh.soup.vertices[t[1]], d = mesh.soup.vertices[t[2]];
      points.push_back((a + c) * 0.5f);                       // on an edge when the midpoint is exact
      points.push_back((a + c + d) * (1.0f / 3.0f));          // on or next to a face
      points.push_back(a + (c - a) * 0.25f + (d - a) * 0.25f);
    }
    // Points on the cube's faces and edges, exactly (its corners are +-0.5).
    if (mesh.name == "cube")
      for (float x : {-0.5f, -0.25f, 0.0f, 0.5f})
        for (float y : {-0.5f, 0.125f, 0.5f}) points.push_back({x, y, 0.5f}), points.push_back({0.5f, x, y});
    for (const Vec3f& p : points) {
      const PointSide want = cgal_side(reference, p), got = query.side(p);
      if (got != want) FAIL_CHECK("point " << p.x << " " << p.y << " " << p.z << ": " << point_side_name(got)
                                           << ", CGAL says " << point_side_name(want));
      surface += want == PointSide::OnSurface;
      inside_count += want == PointSide::Inside;
    }
    total += points.size();
  }
  CHECK(total >= 100000);
  CHECK(surface > 400);  // every vertex, exact edge points, the cube's face points
  CHECK(inside_count > 10000);
}

TEST_CASE("inside: open meshes are reported, and the CLI answers per point and rejects bad points files", "[inside][cli]") {
  CHECK(open_or_inconsistent_edges(make_default_scene()) > 0);  // the ground grid has a border
  const std::string pts = test::temp_path("inside_points.txt"), out = test::temp_path("inside_points.out");
  {
    std::ofstream f(pts);
    f << "# a comment\n0 0 0\n\n0.5 0.5 0.5\n2 2 2\n0.25 0.25 -0.5\n";
  }
  const test::CliRun r = test::bsprt_cli("inside " + test::scene_path("cube.obj") + " " + pts + " -o " + out);
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("4 points: 1 inside, 1 outside, 2 on the surface") != std::string::npos);
  std::ifstream in(out);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  CHECK(lines == std::vector<std::string>{"inside", "surface", "outside", "surface"});
  {
    std::ofstream f(pts);
    f << "0 0 0\n1 2\n";
  }
  const test::CliRun bad = test::bsprt_cli("inside " + test::scene_path("cube.obj") + " " + pts + " -o " + out);
  CHECK(bad.status == 1);
  CHECK(bad.output.find(pts + ":2") != std::string::npos);
  {
    std::ofstream f(pts);
    f << "0 0 0\n";
  }
  const test::CliRun open = test::bsprt_cli("inside default " + pts + " -o " + out);
  INFO(open.output);
  CHECK(open.status == 0);
  CHECK(open.output.find("warning:") != std::string::npos);
}

}  // namespace bsprt

namespace bsprt {

TEST_CASE("trace --all-hits equals exact brute-force crossings, and --occluded equals the exact hits", "[inside][cli]") {
  const std::string scene = test::scene_path("suzanne.obj"), rays = test::temp_path("allhits.rays");
  for (const char* kind : {"vertex", "edge"}) {
    INFO(kind);
    REQUIRE(test::bsprt_cli("gen-rays " + scene + " --kind " + std::string(kind) + " -n 1500 --seed 4 -o " + rays)
                .status == 0);
    const std::string csv = test::temp_path("allhits.csv");
    const test::CliRun r = test::bsprt_cli("trace " + scene + " " + rays + " --all-hits -o " + csv);
    INFO(r.output);
    REQUIRE(r.status == 0);
    // The reference: every triangle, the same exact crossing decision.
    TriangleSoup soup = load_mesh(scene);
    classify_degenerate(soup);
    const CertifiedIntersector cert(soup);
    std::vector<std::uint32_t> all(soup.size());
    for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
    std::vector<std::string> want = {"ray,prim,t,side"};
    const std::vector<Ray> rs = read_rays(rays);
    for (std::size_t i = 0; i < rs.size(); ++i) {
      std::vector<CertifiedIntersector::Crossing> xs;
      cert.crossings(rs[i], all, xs, nullptr);
      std::sort(xs.begin(), xs.end(), [](const auto& a, const auto& b) { return a.t < b.t || (a.t == b.t && a.prim < b.prim); });
      for (const auto& x : xs) want.push_back(fmt::format("{},{},{},{}", i, x.prim, x.t, x.side));
    }
    std::ifstream in(csv);
    std::vector<std::string> got;
    for (std::string line; std::getline(in, line);) got.push_back(line);
    CHECK(got.size() > rs.size());  // most rays cross the mesh at least twice
    CHECK(got == want);
    // --occluded: 1 exactly where the exact reference hits; bsp and kd stop at
    // their first leaf with a hit, bvh8 at its first hit.
    const std::string occ = test::temp_path("allhits.occ"), ref = test::temp_path("allhits.exact.hits");
    REQUIRE(test::bsprt_cli("trace " + scene + " " + rays + " --accel exact -o " + ref).status == 0);
    const std::vector<Hit> exact = read_hits(ref);
    for (const char* accel : {"bsp", "kd", "bvh8"}) {
      INFO(accel);
      REQUIRE(test::bsprt_cli("trace " + scene + " " + rays + " --occluded --accel " + accel + " -o " + occ).status == 0);
      std::ifstream o(occ);
      std::size_t i = 0, ones = 0;
      for (std::string line; std::getline(o, line); ++i) {
        REQUIRE(i < exact.size());
        CHECK(line == (exact[i].hit() ? "1" : "0"));
        ones += line == "1";
      }
      CHECK(i == exact.size());
      CHECK(ones > 0);
    }
  }
  CHECK(test::bsprt_cli("trace " + scene + " " + rays + " --all-hits --accel bsp -o " + test::temp_path("x.csv"))
            .status == 2);
  CHECK(test::bsprt_cli("trace " + scene + " " + rays + " --all-hits --occluded -o " + test::temp_path("x.csv"))
            .status == 2);
}

}  // namespace bsprt

namespace bsprt {

// Found by a differential review (2026-12-07): the parity ray from a point
// near -FLT_MAX entered this cube at a finite t and left it at a t rounding to
// +inf, which the nearest-hit convention drops: one crossing, "inside".
TEST_CASE("inside: a point near -FLT_MAX outside a small cube is outside", "[inside][regression]") {
  // The cube (corners at +-0.5, scaled to half-size 1e27) is centred where
  // the parity ray from p reaches t = FLT_MAX + half an ulp, where a t starts
  // to round to +inf: it enters below that t and leaves above it.
  const float M = std::numeric_limits<float>::max();
  const Vec3f p{-M, -0.375f * M, -0.1875f * M};
  const double threshold = 0x1.ffffffp127;
  const Vec3f centre{float(double(p.x) + threshold), float(double(p.y) + threshold * 0.375),
                     float(double(p.z) + threshold * 0.1875)};
  TriangleSoup cube = load_mesh(test::scene_path("cube.obj"));
  for (Vec3f& v : cube.vertices) v = centre + v * 2e27f;
  classify_degenerate(cube);
  const InsideQuery q(cube);
  CHECK(q.side(centre) == PointSide::Inside);
  CHECK(q.side(p) == PointSide::Outside);
  CHECK(q.side({-M, 0, 0}) == PointSide::Outside);
  CHECK(q.side({M, M, M}) == PointSide::Outside);
}

// Found by the same review: --all-hits wrote t = -0 for a ray from a vertex,
// where the nearest-hit query writes +0.
TEST_CASE("crossings: a crossing at t = 0 is +0", "[inside][regression]") {
  TriangleSoup cube = load_mesh(test::scene_path("cube.obj"));
  classify_degenerate(cube);
  const CertifiedIntersector cert(cube);
  int zeros = 0;
  for (const Vec3f& v : cube.vertices)
    for (const Vec3f d : {Vec3f{-v.x, -v.y, -v.z}, Vec3f{-v.x, 0.25f * v.y, -0.5f * v.z}}) {
      Ray r;
      r.org = v, r.dir = d;
      std::vector<std::uint32_t> all(cube.size());
      for (std::uint32_t t = 0; t < cube.size(); ++t) all[t] = t;
      std::vector<CertifiedIntersector::Crossing> out;
      cert.crossings(r, all, out, nullptr);
      for (const auto& c : out)
        if (c.t == 0) {
          ++zeros;
          CHECK(!std::signbit(c.t));
        }
    }
  CHECK(zeros > 0);
}

}  // namespace bsprt
