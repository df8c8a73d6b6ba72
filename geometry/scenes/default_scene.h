#pragma once
/// \file default_scene.h
/// Scenes generated in code: the embedded default scene (ground plane,
/// icosphere, torus knot) and the shapes it is made of, reused by tests and
/// `bsprt gen`. Nothing here is read from a file.

#include "geometry/scenes/camera.h"
#include "geometry/core/triangle_soup.h"

namespace bsprt {

/// A closed icosphere: the icosahedron subdivided `levels` times, vertices
/// projected onto the sphere (20 * 4^levels triangles, outward winding).
TriangleSoup make_icosphere(Vec3f center, float radius, int levels);

/// A closed tube of radius `tube` around a (p, q) torus knot of radius `radius`
/// (2 * segments * sides triangles).
TriangleSoup make_torus_knot(Vec3f center, float radius, float tube, int p, int q, int segments,
                             int sides);

/// A square grid in the plane y = `y`, `n` x `n` quads (2 n^2 triangles).
TriangleSoup make_ground(Vec3f center, float half_size, int n);

/// The embedded default scene: ground grid, icosphere and torus knot, about
/// 6,600 triangles.
TriangleSoup make_default_scene();

/// The camera that frames the default scene.
Camera default_scene_camera();

}  // namespace bsprt
