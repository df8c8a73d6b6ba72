/// \file bvh8_traverse.cpp
/// Bvh8Tracer and its fallback for coordinates so large that p - o could overflow.
#include "traverse/bvh/bvh8_traverse.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "bsprt/error.h"
#include "traverse/bvh/bvh8_kernel.h"
#include "traverse/simd/cpu_features.h"
#include "traverse/watertight.h"

namespace bsprt {

namespace {

float max_abs(const Vec3f& p) { return std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}); }

}  // namespace

Bvh8Tracer::Bvh8Tracer(Bvh8Tree tree) : tree_(std::move(tree)) {
  try {
    tree_.validate();
  } catch (const std::logic_error& e) {
    throw UsageError(std::string("bvh8 tree is not valid: ") + e.what());
  }
  if (tree_.depth > detail::kBvh8MaxDepth)
    throw UsageError("bvh8 tree deeper than " + std::to_string(detail::kBvh8MaxDepth) + " levels");
  for (const LeafTriangle& t : tree_.triangles)
    for (const Vec3f& p : t.v) huge_scene_ = huge_scene_ || !(max_abs(p) <= detail::kBvh8Huge);
  isa_ = detected_isa() >= Isa::Avx2 ? detected_isa() : Isa::Scalar;
}

void Bvh8Tracer::set_kernel_isa(Isa isa) {
  if (int(isa) > int(detected_isa())) throw UsageError("bvh8: this CPU has no " + isa_name(isa));
  isa_ = isa == Isa::Sse42 ? Isa::Scalar : isa;
}

void Bvh8Tracer::shrink_boxes_for_testing() {
  const float inf = std::numeric_limits<float>::infinity();
  for (Bvh8Node& n : tree_.nodes)
    for (int i = 0; i < 8; ++i) {
      if (n.child[i] == 0) continue;  // keep empty slots empty
      for (int k = 0; k < 3; ++k) {
        n.box[2 * k][i] = std::nextafter(n.box[2 * k][i], inf);
        n.box[2 * k + 1][i] = std::nextafter(n.box[2 * k + 1][i], -inf);
      }
    }
}

Hit Bvh8Tracer::trace_every_triangle(const Ray& ray, RayCounters* counters) const {
  if (exact_leaf_) {
    NearestHit best;
    exact_leaf_->intersect(ray, tree_.prims, tree_.triangles.data(), best, counters);
    return best.hit;
  }
  Hit hit;
  const WatertightRay wr = watertight_precompute(ray);
  if (counters) counters->triangle_tests += tree_.prims.size();
  for (std::size_t i = 0; i < tree_.prims.size(); ++i) {
    const LeafTriangle& t = tree_.triangles[i];
    intersect_watertight_closest(wr, t.v[0], t.v[1], t.v[2], tree_.prims[i], hit);
  }
  return hit;
}

Hit Bvh8Tracer::run(const detail::Bvh8View& v, const Ray& ray, RayCounters* counters) const {
  switch (isa_) {
    case Isa::Avx512:
      return detail::bvh8_trace_avx512(v, ray, counters);
    case Isa::Avx2:
      return detail::bvh8_trace_avx2(v, ray, counters);
    default:
      return detail::bvh8_trace_base(v, ray, counters);
  }
}

bool Bvh8Tracer::run_occluded(const detail::Bvh8View& v, const Ray& ray, RayCounters* counters) const {
  switch (isa_) {
    case Isa::Avx512:
      return detail::bvh8_occluded_avx512(v, ray, counters);
    case Isa::Avx2:
      return detail::bvh8_occluded_avx2(v, ray, counters);
    default:
      return detail::bvh8_occluded_base(v, ray, counters);
  }
}

Hit Bvh8Tracer::trace(const Ray& ray, RayCounters* counters) const {
  if (tree_.over_bsp) throw UsageError("bvh8: a tree over a BSP is traced through its BspTracer");
  if (huge_scene_ || !detail::bvh8_origin_in_range(ray)) {
    if (counters) ++counters->rays;
    return is_valid(ray) ? trace_every_triangle(ray, counters) : Hit{};
  }
  return run(view(), ray, counters);
}

void Bvh8Tracer::trace_batch(std::span<const Ray> rays, std::span<Hit> hits, int packet_width,
                             RayCounters* counters) const {
  if (tree_.over_bsp) throw UsageError("bvh8: a tree over a BSP is traced through its BspTracer");
  check_trace_batch(rays.size(), hits.size(), 1);  // as many hits as rays; single rays whatever packet_width
  if (huge_scene_) return Accelerator::trace_batch(rays, hits, packet_width, counters);
  const auto fallback = [](const void* ctx, const Ray& ray, RayCounters* c) {
    return static_cast<const Bvh8Tracer*>(ctx)->trace(ray, c);
  };
  const detail::Bvh8View v = view();
  switch (isa_) {
    case Isa::Avx512:
      return detail::bvh8_trace_batch_avx512(v, rays.data(), hits.data(), rays.size(), counters, fallback, this);
    case Isa::Avx2:
      return detail::bvh8_trace_batch_avx2(v, rays.data(), hits.data(), rays.size(), counters, fallback, this);
    default:
      return detail::bvh8_trace_batch_base(v, rays.data(), hits.data(), rays.size(), counters, fallback, this);
  }
}

bool Bvh8Tracer::occluded(const Ray& ray, RayCounters* counters) const {
  if (tree_.over_bsp) throw UsageError("bvh8: a tree over a BSP is traced through its BspTracer");
  if (huge_scene_ || !detail::bvh8_origin_in_range(ray)) return trace(ray, counters).hit();
  return run_occluded(view(), ray, counters);
}

Hit Bvh8Tracer::trace_with(const Ray& ray, detail::Bvh8SubtreeFn fn, void* ctx, RayCounters* counters) const {
  detail::Bvh8View v = view();
  v.subtree = fn;
  v.subtree_ctx = ctx;
  return run(v, ray, counters);
}

bool Bvh8Tracer::occluded_with(const Ray& ray, detail::Bvh8SubtreeFn fn, void* ctx, RayCounters* counters) const {
  detail::Bvh8View v = view();
  v.subtree = fn;
  v.subtree_ctx = ctx;
  return run_occluded(v, ray, counters);
}

detail::Bvh8View Bvh8Tracer::view() const {
  return {tree_.nodes.data(), tree_.leaf_soa.data(), tree_.prims.data(), tree_.triangles.data(), exact_leaf_, nullptr,
          nullptr};
}

}  // namespace bsprt
