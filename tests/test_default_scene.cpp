// The embedded default scene and the generated shapes: sizes, closedness,
// the camera sees it, and generated ray sets are what they claim.
#include <catch2/catch.hpp>

#include <map>
#include <utility>

#include "geometry/scenes/default_scene.h"
#include "bsprt/error.h"
#include "geometry/scenes/ray_gen.h"

using namespace bsprt;

namespace {
/// Every undirected edge of a closed, consistently oriented mesh is used once
/// in each direction.
bool is_closed_and_oriented(const TriangleSoup& s) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const TriIndices& t : s.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    if (count != 1) return false;
    auto it = directed.find({edge.second, edge.first});
    if (it == directed.end() || it->second != 1) return false;
  }
  return true;
}
}  // namespace

TEST_CASE("icosphere is closed, oriented, on the sphere", "[default_scene]") {
  const TriangleSoup s = make_icosphere({1, 2, 3}, 2.0f, 2);
  CHECK(s.size() == 20u * 16u);
  CHECK(s.degenerate_count() == 0);
  CHECK(is_closed_and_oriented(s));
  for (const Vec3f& p : s.vertices) CHECK(length(p - Vec3f{1, 2, 3}) == Approx(2.0f).epsilon(1e-5));
  // Outward winding: the normal points away from the centre.
  for (std::uint32_t t = 0; t < s.size(); ++t) {
    const auto [a, b, c] = s.corners(t);
    CHECK(dot(cross(b - a, c - a), (a + b + c) * (1.0f / 3.0f) - Vec3f{1, 2, 3}) > 0);
  }
}

TEST_CASE("torus knot is a closed tube", "[default_scene]") {
  const TriangleSoup s = make_torus_knot({0, 0, 0}, 1.0f, 0.2f, 2, 3, 64, 8);
  CHECK(s.size() == 2u * 64u * 8u);
  CHECK(s.degenerate_count() == 0);
  CHECK(is_closed_and_oriented(s));
}

TEST_CASE("default scene has a few thousand triangles and the camera frames it", "[default_scene]") {
  const TriangleSoup s = make_default_scene();
  CHECK(s.size() == 2u * 16u * 16u + 20u * 64u + 2u * 192u * 12u);
  CHECK(s.degenerate.size() == s.size());
  CHECK(s.degenerate_count() == 0);
  const Camera cam = default_scene_camera();
  const Box3f b = s.bounds();
  CHECK_FALSE(b.empty());
  // The look-at point lies inside the scene's box, the eye outside it.
  for (int k = 0; k < 3; ++k) {
    CHECK(cam.vi[k] >= b.lo[k]);
    CHECK(cam.vi[k] <= b.hi[k]);
  }
  CHECK((cam.vp.y > b.hi.y || cam.vp.z < b.lo.z));
}

TEST_CASE("generated ray sets aim where they say", "[ray_gen]") {
  const TriangleSoup s = make_icosphere({0, 0, 0}, 1.0f, 1);
  for (RaySetKind kind : {RaySetKind::Random, RaySetKind::Vertex, RaySetKind::Edge}) {
    const auto a = make_rays(kind, s, 200, 7);
    const auto b = make_rays(kind, s, 200, 7);
    REQUIRE(a.size() == 200);
    for (std::size_t i = 0; i < a.size(); ++i) {
      CHECK(is_valid(a[i]));
      CHECK(a[i].org == b[i].org);  // deterministic for a seed
      CHECK(a[i].dir == b[i].dir);
    }
  }
  // Vertex rays pass (within rounding) through a vertex of the mesh at t = 1.
  for (const Ray& r : vertex_rays(s, 100, 3)) {
    const Vec3f p = r.org + r.dir;
    float best = 1e30f;
    for (const Vec3f& v : s.vertices) best = std::min(best, length(p - v));
    CHECK(best < 1e-5f);
  }
  CHECK(primary_rays(default_scene_camera(), 32, 24).size() == 32u * 24u);
  // Tiled primary rays are the same rays, reordered tile by tile (20 x 13: partial tiles).
  const auto flat = primary_rays(default_scene_camera(), 20, 13);
  const auto tiled = tiled_primary_rays(default_scene_camera(), 20, 13, 8);
  REQUIRE(tiled.size() == flat.size());
  CHECK(tiled[1].dir == flat[1].dir);          // (1, 0): first tile's first row
  CHECK(tiled[8].dir == flat[20].dir);         // (0, 1): first tile's second row
  CHECK(tiled[64].dir == flat[8].dir);         // (8, 0): second tile starts
  CHECK(tiled.back().dir == flat.back().dir);  // (19, 12): last pixel last
  CHECK_THROWS_AS(parse_ray_set("sideways"), UsageError);
}
