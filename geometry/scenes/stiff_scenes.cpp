/// \file stiff_scenes.cpp
/// The stiff scenes of stiff_scenes.h. Coordinates are chosen so that the hard
/// configurations are exact in float (integer or dyadic coordinates, vertices
/// one ulp apart) rather than approximately stiff.
#include "geometry/scenes/stiff_scenes.h"

#include <cmath>
#include <functional>
#include <numbers>
#include <utility>

#include "geometry/scenes/default_scene.h"
#include "bsprt/error.h"
#include "robust/degenerate.h"

namespace bsprt {
namespace {

/// Adds triangle (a, b, c) with its own three vertices.
void add_tri(TriangleSoup& s, Vec3f a, Vec3f b, Vec3f c) {
  const auto n = std::uint32_t(s.vertices.size());
  s.vertices.insert(s.vertices.end(), {a, b, c});
  s.triangles.push_back({n, n + 1, n + 2});
}

/// The float `steps` ulps above `x`.
float ulps_up(float x, int steps) {
  for (int i = 0; i < steps; ++i) x = std::nextafter(x, INFINITY);
  return x;
}

/// Long thin slivers (height down to 1e-7 of the length) and needles (one edge
/// of a single ulp), in several orientations.
TriangleSoup slivers() {
  TriangleSoup s;
  for (int k = 0; k < 32; ++k) {
    const float y = 0.125f * float(k), h = std::pow(10.0f, -float(k % 8));
    add_tri(s, {0, y, 0}, {4, y, 0.0625f * float(k % 3)}, {2, y + h, 0.03125f * float(k % 5)});
  }
  for (int k = 0; k < 32; ++k) {
    const Vec3f a{0.25f * float(k % 8), 5.0f + 0.25f * float(k / 8), 1.0f};
    const Vec3f b{ulps_up(a.x, 1 + k % 3), a.y, a.z};
    const Vec3f c = a + Vec3f{0.5f, 0.25f * float(k % 2), -3.0f};
    add_tri(s, a, b, c);
  }
  return s;
}

/// Exactly degenerate triangles (repeated corners, collinear corners) beside
/// near-degenerate ones (a corner one ulp off the line, corners collinear in
/// the reals but not after rounding to float), over a backdrop of good ones.
TriangleSoup degenerate_mix() {
  TriangleSoup s;
  for (int k = 0; k < 8; ++k) {
    const float z = float(k);
    add_tri(s, {0, 0, z}, {0, 0, z}, {1, 1, z});                        // repeated corner
    add_tri(s, {0, 0, z}, {1, 1, z + 1}, {2, 2, z + 2});                // collinear, exact
    add_tri(s, {0, 0, z}, {2, 0, z}, {1, ulps_up(0.0f, 1 + k), z});    // one (subnormal) ulp off
    add_tri(s, {0, 1, z}, {2, 1, z}, {1, ulps_up(1.0f, 1 + k), z});    // one ulp off at 1
    add_tri(s, {0.1f, 0.1f, z + 0.1f}, {0.2f, 0.2f, z + 0.2f}, {0.3f, 0.3f, z + 0.3f});  // rounding breaks collinearity
    add_tri(s, {-1, -1, z}, {3, -1, z}, {-1, 3, z + 0.5f});             // a good one
  }
  return s;
}

/// A triangle duplicated four times, overlapping coplanar triangles, parallel
/// copies one ulp apart and triangles crossing them.
TriangleSoup stacks() {
  TriangleSoup s;
  const Vec3f a{0, 0, 1}, b{2, 0, 1}, c{0, 2, 1};
  for (int k = 0; k < 4; ++k) add_tri(s, a, b, c);
  for (int k = 1; k < 6; ++k) {
    const Vec3f d{0.25f * float(k), 0.125f * float(k), 0};
    add_tri(s, a + d, b + d, c + d);  // coplanar, overlapping
  }
  for (int k = 1; k < 6; ++k) {
    const float z = ulps_up(1.0f, k);
    add_tri(s, {0, 0, z}, {2, 0, z}, {0, 2, z});  // parallel, k ulps above
  }
  add_tri(s, {0.5f, -1, 0}, {0.5f, 3, 0}, {0.5f, 1, 2});  // crosses the stack in x = 0.5
  add_tri(s, {-1, 0.5f, 2}, {3, 0.5f, 2}, {1, 0.5f, 0});  // crosses it in y = 0.5
  return s;
}

/// A closed box [0, n]^3 whose faces are n x n grids of unit quads: every
/// vertex lies on the integer axis planes a kd build likes to split at.
TriangleSoup grid_box(int n) {
  TriangleSoup s;
  const float m = float(n);
  const auto quad = [&](Vec3f p, Vec3f u, Vec3f v) {
    add_tri(s, p, p + u, p + u + v);
    add_tri(s, p, p + u + v, p + v);
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const float x = float(i), y = float(j);
      quad({x, y, 0}, {0, 1, 0}, {1, 0, 0});   // z = 0, facing -z
      quad({x, y, m}, {1, 0, 0}, {0, 1, 0});   // z = n, facing +z
      quad({x, 0, y}, {1, 0, 0}, {0, 0, 1});   // y = 0
      quad({x, m, y}, {0, 0, 1}, {1, 0, 0});   // y = n
      quad({0, x, y}, {0, 0, 1}, {0, 1, 0});   // x = 0
      quad({m, x, y}, {0, 1, 0}, {0, 0, 1});   // x = n
    }
  return s;
}

/// A closed bicone: `n` fan triangles around each of two apexes (0, 0, ±1),
/// ring of radius 1 in z = 0, shared vertices.
TriangleSoup bicone(int n) {
  TriangleSoup s;
  s.vertices.push_back({0, 0, 1});
  s.vertices.push_back({0, 0, -1});
  for (int k = 0; k < n; ++k) {
    const double phi = 2.0 * std::numbers::pi * k / n;
    s.vertices.push_back({float(std::cos(phi)), float(std::sin(phi)), 0.0f});
  }
  for (std::uint32_t k = 0; k < std::uint32_t(n); ++k) {
    const std::uint32_t a = 2 + k, b = 2 + (k + 1) % std::uint32_t(n);
    s.triangles.push_back({0, a, b});
    s.triangles.push_back({1, b, a});
  }
  return s;
}

/// The composite the far/scaled cases move: a closed icosphere at the origin
/// (the `inside` point), a bicone, stacks and slivers beside it.
TriangleSoup composite(int detail) {
  TriangleSoup s = make_icosphere({0, 0, 0}, 1.0f, 2 + detail);
  append(s, transformed_soup(bicone(64 << detail), 1.0f, {3, 0, 0}));
  append(s, transformed_soup(stacks(), 0.5f, {-4, -0.5f, -0.5f}));
  append(s, transformed_soup(slivers(), 0.25f, {-0.5f, 1.5f, 0}));
  return s;
}

StiffScene finish(std::string name, std::string description, TriangleSoup soup) {
  StiffScene sc;
  sc.name = std::move(name);
  sc.description = std::move(description);
  sc.soup = std::move(soup);
  classify_degenerate(sc.soup);
  return sc;
}

StiffScene closed(StiffScene sc, Vec3f inside, float radius) {
  sc.closed = true;
  sc.inside = inside;
  sc.inside_radius = radius;
  return sc;
}

/// The composite scaled by `scale` and moved to `shift`.
StiffScene moved(const std::string& name, const std::string& what, int detail, float scale, Vec3f shift) {
  return closed(finish(name, what, transformed_soup(composite(detail), scale, shift)), shift, 0.5f * scale);
}

using Maker = std::function<StiffScene(int)>;

const std::vector<std::pair<std::string, Maker>>& makers() {
  static const std::vector<std::pair<std::string, Maker>> m = {
      {"slivers", [](int) { return finish("slivers", "slivers (height down to 1e-7 of length) and needles (1-ulp edges)", slivers()); }},
      {"degenerate", [](int) { return finish("degenerate", "degenerate (repeated, collinear) and near-degenerate (1 ulp off) triangles", degenerate_mix()); }},
      {"stacks", [](int) { return finish("stacks", "duplicated, coplanar overlapping and 1-ulp-apart parallel triangles, crossed", stacks()); }},
      {"grid_box", [](int d) { return closed(finish("grid_box", "closed box of unit quads: vertices on integer split planes", grid_box(4 << d)), Vec3f(float(2 << d), float(2 << d), float(2 << d)), 1.0f); }},
      {"fan", [](int d) { return closed(finish("fan", "closed bicone: 2 fans of many triangles around one vertex", bicone(256 << d)), {0, 0, 0}, 0.5f); }},
      {"sphere", [](int d) { return closed(finish("sphere", "finely tessellated closed icosphere", make_icosphere({0, 0, 0}, 1.0f, 4 + d)), {0, 0, 0}, 0.5f); }},
      {"torus", [](int d) { return closed(finish("torus", "finely tessellated closed torus", make_torus({0, 0, 0}, 1.0f, 0.25f, 96 << d, 24 << d)), {1, 0, 0}, 0.125f); }},
      {"far_1e5", [](int d) { return moved("far_1e5", "composite translated to (1e5, 1e5, 1e5)", d, 1.0f, Vec3f{1e5f, 1e5f, 1e5f}); }},
      {"far_1e7", [](int d) { return moved("far_1e7", "composite scaled by 100, translated to (1e7, 0, 0): float spacing 1", d, 100.0f, {1e7f, 0, 0}); }},
      {"tiny_1e-6", [](int d) { return moved("tiny_1e-6", "composite scaled by 1e-6", d, 1e-6f, {0, 0, 0}); }},
      {"huge_1e6", [](int d) { return moved("huge_1e6", "composite scaled by 1e6", d, 1e6f, {0, 0, 0}); }},
  };
  return m;
}

}  // namespace

std::vector<std::string> stiff_scene_names() {
  std::vector<std::string> names;
  for (const auto& [name, maker] : makers()) names.push_back(name);
  return names;
}

StiffScene make_stiff_scene(const std::string& name, int detail) {
  if (detail < 0 || detail > 4) throw UsageError("stiff scene detail must be in 0..4, not " + std::to_string(detail));
  for (const auto& [n, maker] : makers())
    if (n == name) return maker(detail);
  std::string names;
  for (const std::string& n : stiff_scene_names()) names += (names.empty() ? "" : ", ") + n;
  throw UsageError("unknown stiff scene '" + name + "' (expected one of: " + names + ")");
}

TriangleSoup make_torus(Vec3f center, float major, float minor, int nu, int nv) {
  TriangleSoup s;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2.0 * std::numbers::pi * i / nu, v = 2.0 * std::numbers::pi * j / nv;
      const double r = major + minor * std::cos(v);
      s.vertices.push_back(center + Vec3f{float(r * std::cos(u)), float(r * std::sin(u)), float(minor * std::sin(v))});
    }
  const auto id = [&](int i, int j) { return std::uint32_t((i % nu) * nv + (j % nv)); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      s.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      s.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  classify_degenerate(s);
  return s;
}

TriangleSoup transformed_soup(const TriangleSoup& s, float scale, Vec3f shift) {
  TriangleSoup t = s;
  for (Vec3f& p : t.vertices) p = p * scale + shift;
  classify_degenerate(t);
  return t;
}

}  // namespace bsprt
