#pragma once
/// \file stiff_rays.h
/// Stiff ray sets (issue 6, item 2) beside ray_gen.h's: rays lying along
/// triangle edges, grazing triangles, lying in axis planes through vertices,
/// axis-parallel through vertices, from inside closed meshes, and invalid rays
/// (NaN, Inf, zero direction, tnear > tfar). Deterministic for a given seed.
#include <cstdint>
#include <string>
#include <vector>

#include "bsprt/ray.h"
#include "geometry/core/triangle_soup.h"

namespace bsprt {

/// Kinds of stiff ray set; names as accepted by `bsprt gen --rays`.
enum class StiffRayKind { Vertex, Edge, AlongEdge, Grazing, AxisPlane, AxisParallel, Invalid };

/// Every kind, in a fixed order.
std::vector<StiffRayKind> stiff_ray_kinds();
/// "vertex", "edge", "along-edge", "grazing", "axis-plane", "axis-parallel", "invalid".
std::string stiff_ray_name(StiffRayKind kind);
/// Parses a stiff ray-set name; throws UsageError for unknown names.
StiffRayKind parse_stiff_ray_kind(const std::string& name);

/// `n` rays of `kind` over the non-degenerate triangles of `soup` (throws
/// UsageError when there is none, except for Invalid).
/// - Vertex, Edge: vertex_rays, edge_rays of ray_gen.h.
/// - AlongEdge: starting one edge length before a corner, pointing along the edge.
/// - Grazing: through an interior point, at about 1e-4 rad to the triangle's plane.
/// - AxisPlane: aimed at a vertex, lying exactly in an axis plane through it.
/// - AxisParallel: along ±x, ±y or ±z, exactly through a vertex or an edge point.
/// - Invalid: NaN or Inf in origin or direction, zero direction, tnear > tfar; all miss.
std::vector<Ray> stiff_rays(StiffRayKind kind, const TriangleSoup& soup, std::size_t n, std::uint64_t seed);

/// `n` rays with origins uniform in the ball (center, radius); even rays have
/// uniform random directions, odd ones are aimed at random vertices of `soup`.
/// From inside a closed mesh none of them may escape.
std::vector<Ray> inside_rays(const TriangleSoup& soup, Vec3f center, float radius, std::size_t n,
                             std::uint64_t seed);

}  // namespace bsprt
