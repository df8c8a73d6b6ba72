#pragma once
/// \file load_mesh.h
/// Loading OBJ, PLY (ascii and binary), OFF and STL through OpenMesh's IO layer
/// with a custom importer that keeps every face (OpenMesh's halfedge mesh drops
/// non-manifold faces; we never do). Triangle numbering follows formats.md.

#include <cstddef>
#include <string>

#include "geometry/core/triangle_soup.h"

namespace bsprt {

/// What to do with input that is legal to read but unusual.
struct LoadOptions {
  /// Non-finite (NaN/Inf) vertex coordinates used by a face: false (default) =
  /// throw InputError naming the vertex; true = keep the triangles, flag them
  /// degenerate (never hit) and count them in LoadReport::nonfinite_triangles.
  bool allow_nonfinite = false;
};

/// Counts and timing of one load, for `bsprt info` and load summaries.
struct LoadReport {
  std::string format;                   ///< "obj", "ply", "off", "stl"
  std::size_t vertices = 0;             ///< vertices declared in the file
  std::size_t unreferenced_vertices = 0;///< vertices no face uses
  std::size_t faces = 0;                ///< faces (polygons) read
  std::size_t triangles = 0;            ///< triangles after fan triangulation
  std::size_t degenerate = 0;           ///< triangles with repeated/collinear corners (kept, never hit)
  std::size_t nonfinite_triangles = 0;  ///< triangles with a NaN/Inf corner (only with allow_nonfinite)
  double seconds = 0.0;                 ///< wall time of the load
};

/// Loads a mesh file into a triangle soup with `degenerate` flags set. Throws
/// InputError (file, line or element, what is wrong) on any malformed input:
/// unknown extension, empty file, bad or out-of-range indices, truncated binary
/// data, counts that lie, non-finite coordinates (unless allowed).
TriangleSoup load_mesh(const std::string& path, const LoadOptions& options = {},
                       LoadReport* report = nullptr);

}  // namespace bsprt
