#pragma once
/// \file ray_gen.h
/// Ray sets every tool traces (`bsprt gen-rays`, tests, benchmarks): primary
/// camera rays, random rays, rays aimed at vertices and at edges. Deterministic
/// for a given seed so runs can be compared ray by ray.

#include <cstdint>
#include <string>
#include <vector>

#include "geometry/scenes/camera.h"
#include "bsprt/ray.h"
#include "geometry/core/triangle_soup.h"

namespace bsprt {

/// Kinds of ray set; names as accepted by `--rays`.
enum class RaySetKind { Primary, Random, Vertex, Edge };

/// "primary", "random", "vertex", "edge".
std::string ray_set_name(RaySetKind kind);
/// Parses a ray-set name; throws UsageError for unknown names.
RaySetKind parse_ray_set(const std::string& name);

/// One primary ray per pixel centre, row-major from the top-left pixel.
std::vector<Ray> primary_rays(const Camera& cam, int width, int height);

/// The same rays in `tile` x `tile` pixel tiles (row-major inside a tile, tiles
/// row-major), so consecutive rays, and hence packets, are coherent.
std::vector<Ray> tiled_primary_rays(const Camera& cam, int width, int height, int tile = 8);

/// `n` rays with origins uniform in the scene box enlarged by 10% per side and
/// directions uniform on the sphere.
std::vector<Ray> random_rays(const TriangleSoup& soup, std::size_t n, std::uint64_t seed);

/// `n` rays from random origins (as random_rays) aimed at vertices of random
/// non-degenerate triangles: dir = vertex - origin in float, so the exact ray
/// passes within one rounding of the vertex — the stiff case of docs/robustness.md.
std::vector<Ray> vertex_rays(const TriangleSoup& soup, std::size_t n, std::uint64_t seed);

/// `n` rays from random origins aimed at random points of random triangle edges.
std::vector<Ray> edge_rays(const TriangleSoup& soup, std::size_t n, std::uint64_t seed);

/// Dispatches on `kind`; primary rays use frame_bounds(soup.bounds()) at
/// a square image with about n pixels.
std::vector<Ray> make_rays(RaySetKind kind, const TriangleSoup& soup, std::size_t n, std::uint64_t seed);

}  // namespace bsprt
