#pragma once
/// \file scene.h
/// bsprt's public scene: a triangle soup from arrays or a mesh file, numbered
/// and checked exactly as the `bsprt` CLI numbers and checks it (formats.md).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "bsprt/error.h"
#include "bsprt/vec3.h"

namespace bsprt {

struct TriangleSoup;

/// How unusual but legal input is treated.
struct SceneOptions {
  /// Non-finite (NaN/Inf) coordinates used by a triangle: false = throw
  /// (InputError for files, UsageError for arrays) naming the vertex; true =
  /// keep the triangles, flag them degenerate (never hit) and count them.
  bool allow_nonfinite = false;
};

/// What loading found: the counts the CLI prints in its load summary.
struct SceneSummary {
  std::string source;                     ///< the file, "default", or "arrays"
  std::size_t vertices = 0;               ///< vertices given
  std::size_t unreferenced_vertices = 0;  ///< vertices no triangle uses
  std::size_t triangles = 0;              ///< triangles (polygons fan triangulated)
  std::size_t degenerate = 0;             ///< repeated/collinear corners (exact test) or non-finite: never hit
  std::size_t nonfinite_triangles = 0;    ///< of those, with a NaN/Inf corner (only with allow_nonfinite)
};

/// An immutable triangle scene. Copies share the data; it stays alive as long
/// as any Scene, Tree or Tracer made from it does.
class Scene {
 public:
  /// From flat arrays: `vertices` holds x,y,z per vertex, `indices` three
  /// 0-based vertex indices per triangle (triangle i = indices[3i..3i+2]).
  /// Throws UsageError for sizes that are not multiples of 3, no triangles, an
  /// index out of range, or (unless allowed) a non-finite coordinate.
  static Scene from_arrays(std::span<const float> vertices, std::span<const std::uint32_t> indices,
                           const SceneOptions& options = {});

  /// From an OBJ, PLY, OFF or STL file (every face kept, docs/loading.md), or
  /// the embedded default scene when `path` is "default". Throws InputError
  /// naming the file and line for malformed input.
  static Scene load(const std::string& path, const SceneOptions& options = {});

  /// The embedded default scene (ground grid, icosphere, torus knot).
  static Scene default_scene();

  /// Number of triangles, degenerate ones included (they keep their numbers).
  std::size_t triangle_count() const;
  /// Number of vertices.
  std::size_t vertex_count() const;
  /// The load summary.
  const SceneSummary& summary() const;
  /// Bounds of the non-degenerate triangles' corners.
  Box3f bounds() const;
  /// The 64-bit fingerprint tree files are bound to.
  std::uint64_t fingerprint() const;
  /// Corner k (0..2) of triangle t (bounds checked; throws UsageError).
  Vec3f corner(std::size_t t, int k) const;

  /// bsprt's internal soup (for bsprt's own tools; not part of the stable API).
  const TriangleSoup& soup() const;

 public:
  struct Impl;  ///< the implementation (api/): opaque here

 private:
  explicit Scene(std::shared_ptr<const Impl> impl);
  /// *impl_; a UsageError for an object moved from (whose impl_ is null), not a crash.
  const Impl& impl() const;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace bsprt
