#pragma once
/// \file stiff_scenes.h
/// Stiff and extreme scenes generated in code (issue 6, item 2): slivers and
/// needles, near-degenerate and degenerate triangles, duplicated and coplanar
/// stacks, vertices on likely split planes, fans around one vertex, finely
/// tessellated closed solids, and the same geometry far from the origin or
/// scaled to tiny and huge sizes. Used by tests/test_stiff.cpp, the
/// watertightness test and `bsprt gen`. Deterministic; nothing is read from a file.
#include <string>
#include <vector>

#include "geometry/core/triangle_soup.h"

namespace bsprt {

/// A named stiff scene and what makes it stiff.
struct StiffScene {
  std::string name;         ///< as accepted by `bsprt gen --scene`
  std::string description;  ///< one line for docs and `bsprt gen --list`
  bool closed = false;      ///< a closed (watertight) surface: rays from `inside` cannot escape
  Vec3f inside{};           ///< a point well inside when `closed`
  float inside_radius = 0;  ///< origins within this distance of `inside` are inside
  TriangleSoup soup;        ///< degenerate flags already classified
};

/// Names of every stiff scene, in a fixed order.
std::vector<std::string> stiff_scene_names();

/// Builds the named stiff scene; `detail` (>= 0) scales the tessellation of the
/// closed solids and fans (0 = small, for CI; 2 = fine). Throws UsageError for
/// an unknown name.
StiffScene make_stiff_scene(const std::string& name, int detail = 0);

/// A closed torus around the z axis: `major` radius of the centre circle,
/// `minor` radius of the tube, `nu` x `nv` quads (2 nu nv triangles), shared vertices.
TriangleSoup make_torus(Vec3f center, float major, float minor, int nu, int nv);

/// Returns `s` with every vertex mapped to p * scale + shift (rounded to float;
/// degenerate flags recomputed, since rounding can collapse triangles).
TriangleSoup transformed_soup(const TriangleSoup& s, float scale, Vec3f shift);

}  // namespace bsprt
