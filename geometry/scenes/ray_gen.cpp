#include "geometry/scenes/ray_gen.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "bsprt/error.h"

namespace bsprt {
namespace {

/// Indices of the non-degenerate triangles; rays aim only at those.
std::vector<std::uint32_t> live_triangles(const TriangleSoup& soup) {
  std::vector<std::uint32_t> live;
  live.reserve(soup.size());
  for (std::uint32_t t = 0; t < soup.size(); ++t)
    if (!soup.is_degenerate(t)) live.push_back(t);
  if (live.empty()) throw UsageError("the scene has no non-degenerate triangle to aim rays at");
  return live;
}

struct OriginSampler {
  explicit OriginSampler(const TriangleSoup& soup) {
    const Box3f b = soup.bounds();
    if (!(b.lo.x <= b.hi.x && b.lo.y <= b.hi.y && b.lo.z <= b.hi.z))
      throw UsageError("the scene has no non-degenerate triangle, so it has no box to draw ray origins from");
    const Vec3f pad = b.diagonal() * 0.1f;
    lo = b.lo - pad;
    size = b.diagonal() + pad * 2.0f;
    if (!is_finite(lo) || !is_finite(size))
      throw UsageError("the scene's bounds padded by 10 % overflow float: no box to draw ray origins from");
  }
  Vec3f operator()(std::mt19937_64& rng) const {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    return {lo.x + size.x * u(rng), lo.y + size.y * u(rng), lo.z + size.z * u(rng)};
  }
  Vec3f lo, size;
};

Vec3f random_direction(std::mt19937_64& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float z = 1.0f - 2.0f * u(rng);
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * std::numbers::pi_v<float> * u(rng);
  return {r * std::cos(phi), r * std::sin(phi), z};
}

}  // namespace

std::string ray_set_name(RaySetKind kind) {
  switch (kind) {
    case RaySetKind::Primary: return "primary";
    case RaySetKind::Random: return "random";
    case RaySetKind::Vertex: return "vertex";
    case RaySetKind::Edge: return "edge";
  }
  return "?";
}

RaySetKind parse_ray_set(const std::string& name) {
  for (RaySetKind k : {RaySetKind::Primary, RaySetKind::Random, RaySetKind::Vertex, RaySetKind::Edge})
    if (ray_set_name(k) == name) return k;
  throw UsageError("unknown ray set '" + name + "' (expected primary, random, vertex or edge)");
}

std::vector<Ray> primary_rays(const Camera& cam, int width, int height) {
  return tiled_primary_rays(cam, width, height, std::max({width, height, 1}));  // one tile: row-major
}

std::vector<Ray> tiled_primary_rays(const Camera& cam, int width, int height, int tile) {
  const CameraRays gen(cam, width, height);
  std::vector<Ray> rays;
  rays.reserve(std::size_t(width) * std::size_t(height));
  for (int ty = 0; ty < height; ty += tile)
    for (int tx = 0; tx < width; tx += tile)
      for (int y = ty; y < std::min(ty + tile, height); ++y)
        for (int x = tx; x < std::min(tx + tile, width); ++x) rays.push_back(gen.ray(x, y));
  return rays;
}

std::vector<Ray> random_rays(const TriangleSoup& soup, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const OriginSampler origin(soup);
  std::vector<Ray> rays(n);
  for (Ray& r : rays) {
    r.org = origin(rng);
    r.dir = random_direction(rng);
  }
  return rays;
}

std::vector<Ray> vertex_rays(const TriangleSoup& soup, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const OriginSampler origin(soup);
  const std::vector<std::uint32_t> live = live_triangles(soup);
  std::uniform_int_distribution<std::size_t> pick(0, live.size() - 1);
  std::uniform_int_distribution<int> corner(0, 2);
  std::vector<Ray> rays(n);
  for (Ray& r : rays) {
    const Vec3f target = soup.corner(live[pick(rng)], corner(rng));
    do {
      r.org = origin(rng);
      r.dir = target - r.org;
    } while (r.dir == Vec3f{});
  }
  return rays;
}

std::vector<Ray> edge_rays(const TriangleSoup& soup, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const OriginSampler origin(soup);
  const std::vector<std::uint32_t> live = live_triangles(soup);
  std::uniform_int_distribution<std::size_t> pick(0, live.size() - 1);
  std::uniform_int_distribution<int> edge(0, 2);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Ray> rays(n);
  for (Ray& r : rays) {
    const std::uint32_t t = live[pick(rng)];
    const int e = edge(rng);
    const Vec3f a = soup.corner(t, e), b = soup.corner(t, (e + 1) % 3);
    const Vec3f target = a + (b - a) * u(rng);
    do {
      r.org = origin(rng);
      r.dir = target - r.org;
    } while (r.dir == Vec3f{});
  }
  return rays;
}

std::vector<Ray> make_rays(RaySetKind kind, const TriangleSoup& soup, std::size_t n, std::uint64_t seed) {
  switch (kind) {
    case RaySetKind::Primary: {
      const int side = std::max(1, int(std::lround(std::sqrt(double(n)))));
      return primary_rays(frame_bounds(soup.bounds()), side, side);
    }
    case RaySetKind::Random: return random_rays(soup, n, seed);
    case RaySetKind::Vertex: return vertex_rays(soup, n, seed);
    case RaySetKind::Edge: return edge_rays(soup, n, seed);
  }
  return {};
}

}  // namespace bsprt
