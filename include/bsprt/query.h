#pragma once
/// \file query.h
/// Exact queries on a closed triangle mesh, the library's form of `bsprt
/// inside` and `bsprt trace --all-hits` (docs/exact-leaf-test.md, "Inside
/// queries" and "All hits"): where points lie, and every crossing of a ray.
/// Both are decided exactly, with simulation of simplicity at vertices and
/// edges, so a ray through a shared edge or vertex crosses each sheet once.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "bsprt/ray.h"
#include "bsprt/scene.h"
#include "bsprt/vec3.h"

namespace bsprt {

/// Where a point lies against a closed mesh.
enum class PointSide : std::uint8_t { Outside = 0, Inside = 1, OnSurface = 2 };

/// One crossing of a ray with a triangle (MeshQuery::all_hits).
struct Crossing {
  std::uint64_t ray = 0;  ///< index of the ray in the span given to all_hits (0 for crossings())
  std::uint32_t prim = 0;  ///< triangle number
  float t = 0.0f;          ///< the exact t rounded to the nearest float
  std::int32_t side = 0;   ///< +1 or -1: the sign of n·dir, n = (v1 - v0) x (v2 - v0)
};

/// How a span of points or rays is answered.
struct QueryOptions {
  /// 0 = all cores (oneTBB, blocks of 4096), 1 = the calling thread only, n =
  /// an arena of n threads; at most kMaxThreads (UsageError otherwise). The
  /// answers do not depend on it.
  int threads = 0;
};

/// The exact reference's AABB tree and exact crossing test over one scene,
/// built once. Safe to use from many threads at once.
class MeshQuery {
 public:
  explicit MeshQuery(const Scene& scene);

  /// Edges of non-degenerate triangles (by vertex position) used by other than
  /// exactly two triangles, or twice in the same direction: 0 for a closed,
  /// consistently oriented mesh, where inside and outside are well defined.
  /// Where it is not 0, side() still answers by parity; `bsprt inside` warns.
  std::size_t open_or_inconsistent_edges() const;

  /// Where p lies: OnSurface when a (non-degenerate) triangle contains it, else
  /// Inside or Outside by the parity of a ray's exact crossings. Throws
  /// UsageError for a point with a NaN or infinite coordinate.
  PointSide side(const Vec3f& p) const;
  /// sides[i] = side(points[i]); throws UsageError when the sizes differ or
  /// for a non-finite point (naming its index), before any is answered.
  void sides(std::span<const Vec3f> points, std::span<PointSide> sides, const QueryOptions& options = {}) const;

  /// Every crossing of `ray` with t in [tnear, tfar], ordered by t, then
  /// triangle; an invalid ray (formats.md) has none.
  std::vector<Crossing> crossings(const Ray& ray) const;
  /// The crossings of every ray, ordered by ray, then t, then triangle, each
  /// with its ray's index: the rows of `bsprt trace --all-hits`.
  std::vector<Crossing> all_hits(std::span<const Ray> rays, const QueryOptions& options = {}) const;

 public:
  struct Impl;  ///< the implementation (api/): opaque here

 private:
  /// *impl_; a UsageError for an object moved from (whose impl_ is null), not a crash.
  const Impl& impl() const;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace bsprt
