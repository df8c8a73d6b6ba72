#pragma once
/// \file tracer.h
/// Tracing rays against a scene with any bsprt accelerator, or with the exact
/// reference: nearest hits and occlusion, single rays or spans of rays.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bsprt/ray.h"
#include "bsprt/scene.h"
#include "bsprt/tree.h"

namespace bsprt {

/// How a span of rays is traced.
struct TraceOptions {
  /// 0 = all cores (oneTBB, blocks of 4096 rays), 1 = the calling thread only,
  /// n = an arena of n threads; at most kMaxThreads (UsageError otherwise).
  /// Hits do not depend on it.
  int threads = 0;
  /// 1 = single rays; 4, 8 or 16 = SIMD packets where the mode has them (the
  /// CLI's --packets). Hits of bsprt's own modes do not depend on it; Embree's
  /// packets (embree, embree-fast) are Embree's code and can differ from its
  /// single rays at ties (docs/api.md, "Threads").
  int packet_width = 1;
};

/// One accelerator over one scene. Safe to use from many threads at once.
class Tracer {
 public:
  /// Traces `tree` (built for `scene`) in `mode`:
  ///  - BSP trees: "certified" (default; exact-decision leaf test, every hit's t
  ///    and triangle equal the exact reference's), "float" (certified epsilons, float watertight leaf),
  ///    "zero-eps" (float leaves without the epsilons), "top" (a box top over
  ///    the BSP, exact leaves), "top-float"; "top-certified" is "top";
  ///  - kd-trees: "certified" (the default: exact leaves, --accel kd) or "float" (kd-float).
  /// Any `--accel` name of that tree kind (e.g. "bsp-float") is accepted too.
  /// Throws UsageError for a mode the tree kind has not or a tree of another
  /// scene, and InputError when the tree's sections fail the checks a loader
  /// runs (Tree::load checks only the container and the scene binding).
  Tracer(const Scene& scene, const Tree& tree, std::string_view mode = "certified");

  /// Any `--accel` accelerator by name (brute, brute-certified, exact, embree,
  /// embree-fast, kd, bsp, ...); kd and BSP modes build their tree in memory.
  static Tracer by_name(const Scene& scene, std::string_view accel);
  /// The exact reference (CGAL AABB tree, exact predicates and parameters).
  static Tracer exact(const Scene& scene);
  /// The `--accel` names by_name accepts.
  static std::vector<std::string> accelerators();

  /// The accelerator's `--accel` name ("bsp", "bsp-float", "kd", "exact", ...).
  std::string name() const;
  /// True when every hit's t and triangle equal the exact reference's, bit for
  /// bit (u and v are rounded approximations: docs/exact-leaf-test.md, "The
  /// quantities").
  bool certified() const;
  /// Bytes held by the acceleration structure.
  std::size_t memory_bytes() const;

  /// Nearest hit in [tnear, tfar]; invalid rays miss (formats.md).
  Hit intersect(const Ray& ray) const;
  /// hits[i] = intersect(rays[i]); throws UsageError when the sizes differ.
  void intersect(std::span<const Ray> rays, std::span<Hit> hits, const TraceOptions& options = {}) const;
  /// True when the ray hits anything in [tnear, tfar] (any-hit).
  bool occluded(const Ray& ray) const;
  /// occluded[i] = occluded(rays[i]) as 0/1; throws UsageError when the sizes differ.
  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                const TraceOptions& options = {}) const;

 public:
  struct Impl;  ///< the implementation (api/): opaque here

 private:
  explicit Tracer(std::shared_ptr<const Impl> impl);
  /// *impl_; a UsageError for an object moved from (whose impl_ is null), not a crash.
  const Impl& impl() const;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace bsprt
