/// \file stiff_rays.cpp
/// The stiff ray sets of stiff_rays.h.
#include "geometry/scenes/stiff_rays.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <random>

#include "bsprt/error.h"
#include "geometry/scenes/ray_gen.h"

namespace bsprt {
namespace {

using Rng = std::mt19937_64;

float uniform(Rng& rng, float lo = 0.0f, float hi = 1.0f) { return std::uniform_real_distribution<float>(lo, hi)(rng); }

/// Non-degenerate triangles; throws UsageError when there is none.
std::vector<std::uint32_t> live(const TriangleSoup& soup) {
  std::vector<std::uint32_t> ids;
  for (std::uint32_t t = 0; t < soup.size(); ++t)
    if (!soup.is_degenerate(t)) ids.push_back(t);
  if (ids.empty()) throw UsageError("the scene has no non-degenerate triangle to aim rays at");
  return ids;
}

Vec3f random_unit(Rng& rng) {
  const float z = uniform(rng, -1.0f, 1.0f), phi = uniform(rng, 0.0f, 2.0f * std::numbers::pi_v<float>);
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

Ray ray_of(Vec3f org, Vec3f dir) {
  Ray r;
  r.org = org;
  r.dir = dir;
  return r;
}

/// The scene's extent (largest side of its box), at least 1e-30.
float extent(const TriangleSoup& soup) {
  const Vec3f d = soup.bounds().diagonal();
  return std::max({d.x, d.y, d.z, 1e-30f});
}

Ray along_edge(const TriangleSoup& soup, std::uint32_t t, Rng& rng) {
  const int k = int(rng() % 3);
  const Vec3f a = soup.corner(t, k), b = soup.corner(t, (k + 1) % 3);
  return ray_of(a - (b - a), b - a);
}

/// A grazing ray, or none when its origin would not be finite. The normal and
/// the origin are made in double: in float the cross product of a needle
/// triangle's edges came out 0, the normal NaN, and 73 of 300 rays on the
/// `degenerate` scene were invalid without a word (review of 2026-12-07).
std::optional<Ray> grazing(const TriangleSoup& soup, std::uint32_t t, Rng& rng) {
  const auto [a, b, c] = soup.corners(t);
  float u = uniform(rng), v = uniform(rng);
  if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
  const Vec3f p = a + (b - a) * u + (c - a) * v;
  const Vec3d e = Vec3d(b) - Vec3d(a), n = normalize(cross(e, Vec3d(c) - Vec3d(a)));
  const double side = (rng() & 1) ? 1.0 : -1.0;
  const Vec3f org(Vec3d(p) - e * 2.0 + n * (side * 2e-4 * length(e)));
  const Ray r = ray_of(org, p - org);
  if (!is_valid(r)) return std::nullopt;
  return r;
}

Ray axis_plane(const TriangleSoup& soup, std::uint32_t t, float size, Rng& rng) {
  const Vec3f v = soup.corner(t, int(rng() % 3));
  Vec3f off = random_unit(rng) * size;
  off[int(rng() % 3)] = 0.0f;
  const Vec3f org = v + off;
  Vec3f dir = v - org;
  for (int k = 0; k < 3; ++k)
    if (off[k] == 0.0f) dir[k] = 0.0f;  // exactly in the plane x_k = v_k
  return ray_of(org, dir);
}

Ray axis_parallel(const TriangleSoup& soup, std::uint32_t t, float size, Rng& rng) {
  const int k = int(rng() % 3);
  Vec3f p = soup.corner(t, k);
  const bool edge_point = (rng() & 1) != 0;
  const int axis = int(rng() % 3);
  const float sign = (rng() & 1) ? 1.0f : -1.0f;
  if (edge_point) {
    // The edge's midpoint across the axis, when it is a float there: the ray
    // along the axis through it then meets the edge exactly. A point at a
    // random fraction, rounded to float, missed slanted edges by an ulp
    // (review of 2026-12-07); otherwise the ray goes through the vertex.
    const Vec3f q = soup.corner(t, (k + 1) % 3);
    Vec3f m = p;
    bool exact = true;
    for (int i = 0; i < 3; ++i) {
      if (i == axis) continue;
      const double mid = (double(p[i]) + double(q[i])) / 2;  // exact in double
      m[i] = float(mid);
      exact = exact && double(m[i]) == mid;
    }
    if (exact) p = m;
  }
  Vec3f dir{0, 0, 0};
  dir[axis] = sign;
  Vec3f org = p;
  org[axis] = p[axis] - sign * size;
  return ray_of(org, dir);
}

Ray invalid(std::size_t i, Rng& rng) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN(), kInf = std::numeric_limits<float>::infinity();
  Ray r = ray_of(random_unit(rng), random_unit(rng));
  switch (i % 7) {
    case 0: r.org.x = kNaN; break;
    case 1: r.dir.y = kNaN; break;
    case 2: r.org.z = kInf; break;
    case 3: r.dir.x = -kInf; break;
    case 4: r.dir = {0, 0, 0}; break;
    case 5: r.tnear = 2.0f, r.tfar = 1.0f; break;
    default: r.tnear = kNaN; break;
  }
  return r;
}

}  // namespace

std::vector<StiffRayKind> stiff_ray_kinds() {
  return {StiffRayKind::Vertex,    StiffRayKind::Edge,         StiffRayKind::AlongEdge, StiffRayKind::Grazing,
          StiffRayKind::AxisPlane, StiffRayKind::AxisParallel, StiffRayKind::Invalid};
}

std::string stiff_ray_name(StiffRayKind kind) {
  switch (kind) {
    case StiffRayKind::Vertex: return "vertex";
    case StiffRayKind::Edge: return "edge";
    case StiffRayKind::AlongEdge: return "along-edge";
    case StiffRayKind::Grazing: return "grazing";
    case StiffRayKind::AxisPlane: return "axis-plane";
    case StiffRayKind::AxisParallel: return "axis-parallel";
    case StiffRayKind::Invalid: return "invalid";
  }
  return "?";
}

StiffRayKind parse_stiff_ray_kind(const std::string& name) {
  for (StiffRayKind k : stiff_ray_kinds())
    if (stiff_ray_name(k) == name) return k;
  throw UsageError("unknown stiff ray set '" + name +
                   "' (expected vertex, edge, along-edge, grazing, axis-plane, axis-parallel or invalid)");
}

std::vector<Ray> stiff_rays(StiffRayKind kind, const TriangleSoup& soup, std::size_t n, std::uint64_t seed) {
  if (kind == StiffRayKind::Vertex) return vertex_rays(soup, n, seed);
  if (kind == StiffRayKind::Edge) return edge_rays(soup, n, seed);
  Rng rng(seed);
  std::vector<Ray> rays;
  rays.reserve(n);
  if (kind == StiffRayKind::Invalid) {
    for (std::size_t i = 0; i < n; ++i) rays.push_back(invalid(i, rng));
    return rays;
  }
  const std::vector<std::uint32_t> ids = live(soup);
  const float size = extent(soup);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t t = ids[rng() % ids.size()];
    switch (kind) {
      case StiffRayKind::AlongEdge: rays.push_back(along_edge(soup, t, rng)); break;
      case StiffRayKind::Grazing: {
        // A triangle whose grazing origin would not be finite (a needle far
        // out): another triangle, up to 64 tries; invalid rays are never
        // passed off as grazing ones.
        std::optional<Ray> r = grazing(soup, t, rng);
        for (int tries = 0; !r && tries < 64; ++tries) r = grazing(soup, ids[rng() % ids.size()], rng);
        if (!r) throw UsageError("no grazing ray with a finite origin found for this scene");
        rays.push_back(*r);
        break;
      }
      case StiffRayKind::AxisPlane: rays.push_back(axis_plane(soup, t, size, rng)); break;
      default: rays.push_back(axis_parallel(soup, t, size, rng)); break;
    }
  }
  return rays;
}

std::vector<Ray> inside_rays(const TriangleSoup& soup, Vec3f center, float radius, std::size_t n,
                             std::uint64_t seed) {
  Rng rng(seed);
  const std::vector<std::uint32_t> ids = live(soup);
  std::vector<Ray> rays(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3f org = center + random_unit(rng) * (radius * std::cbrt(uniform(rng)));
    const Vec3f dir = (i & 1) ? soup.corner(ids[rng() % ids.size()], int(rng() % 3)) - org : random_unit(rng);
    rays[i] = ray_of(org, dir);
  }
  return rays;
}

}  // namespace bsprt
