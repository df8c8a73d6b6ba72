#include "geometry/scenes/default_scene.h"

#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include "robust/degenerate.h"

namespace bsprt {
namespace {

std::uint32_t add_vertex(TriangleSoup& s, Vec3f p) {
  s.vertices.push_back(p);
  return std::uint32_t(s.vertices.size() - 1);
}

/// Midpoint of edge (a, b) on the unit sphere, shared between neighbours.
std::uint32_t midpoint(TriangleSoup& s, std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t>& cache,
                       std::uint32_t a, std::uint32_t b) {
  const auto key = std::minmax(a, b);
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  const std::uint32_t m = add_vertex(s, normalize(s.vertices[a] + s.vertices[b]));
  cache.emplace(key, m);
  return m;
}

}  // namespace

TriangleSoup make_icosphere(Vec3f center, float radius, int levels) {
  TriangleSoup s;
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  const std::array<Vec3f, 12> ico = {{{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                      {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                      {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}}};
  for (const Vec3f& p : ico) add_vertex(s, normalize(p));
  s.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> cache;
    std::vector<TriIndices> next;
    next.reserve(s.triangles.size() * 4);
    for (const TriIndices& tri : s.triangles) {
      const std::uint32_t a = midpoint(s, cache, tri[0], tri[1]);
      const std::uint32_t b = midpoint(s, cache, tri[1], tri[2]);
      const std::uint32_t c = midpoint(s, cache, tri[2], tri[0]);
      next.push_back({tri[0], a, c});
      next.push_back({tri[1], b, a});
      next.push_back({tri[2], c, b});
      next.push_back({a, b, c});
    }
    s.triangles = std::move(next);
  }
  for (Vec3f& p : s.vertices) p = center + p * radius;
  classify_degenerate(s);
  return s;
}

TriangleSoup make_torus_knot(Vec3f center, float radius, float tube, int p, int q, int segments,
                             int sides) {
  TriangleSoup s;
  const double two_pi = 2.0 * std::numbers::pi;
  auto curve = [&](double u) {
    const double r = 2.0 + std::cos(q * u);
    return Vec3d{r * std::cos(p * u), r * std::sin(p * u), -std::sin(q * u)} * (radius / 3.0);
  };
  for (int i = 0; i < segments; ++i) {
    const double u = two_pi * i / segments;
    const Vec3d c = curve(u);
    const Vec3d tangent = normalize(curve(u + 1e-4) - curve(u - 1e-4));
    // The (p, q) knot's tangent always has a large xy part, so a frame built
    // against +z is smooth (a curvature frame twists where curvature vanishes).
    const Vec3d normal = normalize(cross(tangent, Vec3d{0, 0, 1}));
    const Vec3d binormal = cross(tangent, normal);
    for (int j = 0; j < sides; ++j) {
      const double v = two_pi * j / sides;
      const Vec3d off = (normal * std::cos(v) + binormal * std::sin(v)) * double(tube);
      add_vertex(s, center + Vec3f(c + off));
    }
  }
  auto idx = [&](int i, int j) { return std::uint32_t((i % segments) * sides + (j % sides)); };
  for (int i = 0; i < segments; ++i)
    for (int j = 0; j < sides; ++j) {
      s.triangles.push_back({idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)});
      s.triangles.push_back({idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)});
    }
  classify_degenerate(s);
  return s;
}

TriangleSoup make_ground(Vec3f center, float half_size, int n) {
  TriangleSoup s;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      add_vertex(s, center + Vec3f{-half_size + 2 * half_size * i / n, 0.0f, -half_size + 2 * half_size * j / n});
  auto idx = [&](int i, int j) { return std::uint32_t(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      s.triangles.push_back({idx(i, j), idx(i, j + 1), idx(i + 1, j + 1)});
      s.triangles.push_back({idx(i, j), idx(i + 1, j + 1), idx(i + 1, j)});
    }
  classify_degenerate(s);
  return s;
}

TriangleSoup make_default_scene() {
  TriangleSoup scene = make_ground({0, 0, 0}, 4.0f, 16);
  append(scene, make_icosphere({-1.3f, 1.0f, 0.3f}, 1.0f, 3));
  append(scene, make_torus_knot({1.4f, 1.25f, -0.2f}, 1.1f, 0.22f, 2, 3, 192, 12));
  return scene;
}

Camera default_scene_camera() {
  Camera cam;
  cam.vp = {0.8f, 3.2f, -6.5f};
  cam.vi = {0.1f, 0.9f, 0.0f};
  cam.vu = {0, 1, 0};
  cam.fov = 45.0f;
  return cam;
}

}  // namespace bsprt
