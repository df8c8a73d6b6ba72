/// \file tracer.cpp
/// bsprt::Tracer (include/bsprt/tracer.h): a row of the accelerator table
/// (builder/accel_factory.h) made over a Scene, with a tree from memory.
#include "bsprt/tracer.h"

#include "api/blocks.h"
#include "builder/accel_factory.h"
#include "geometry/core/fp_env.h"
#include "traverse/embree/embree_tracer.h"

namespace bsprt {

struct Tracer::Impl {
  Scene scene;  // keeps the soup the accelerator points into alive
  std::unique_ptr<Accelerator> accel;
  std::string name;
  bool certified = false;
};

Tracer::Tracer(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

const Tracer::Impl& Tracer::impl() const {
  if (!impl_)
    throw UsageError("bsprt::Tracer used after it was moved from (only assigning to it or destroying it is "
                     "allowed)");
  return *impl_;
}

namespace {

/// The `--accel` name of `mode` on a tree of `kind`.
std::string accel_for(TreeKind kind, std::string_view mode) {
  const std::string m(mode);
  if (kind == TreeKind::Kd) {
    if (m == "certified" || m == "kd") return "kd";
    if (m == "float" || m == "kd-float") return "kd-float";
    throw UsageError("mode '" + m + "' is not a kd-tree mode (certified or float)");
  }
  if (m == "certified") return "bsp";
  if (m == "float") return "bsp-float";
  if (m == "zero-eps") return "bsp-zero-eps";
  if (m == "top" || m == "top-certified") return "bsp-top";  // top-certified: the name before exact leaves became the default
  if (m == "top-float") return "bsp-top-float";
  if (accel_info(m).tree == AccelTree::Bsp) return m;  // throws UsageError for unknown names
  throw UsageError("mode '" + m +
                   "' is not a BSP mode (certified, float, zero-eps, top, top-float or a bsp* accelerator)");
}

std::shared_ptr<Tracer::Impl> make(const Scene& scene, const std::string& accel, const Tree* tree) {
  AccelOptions options;
  if (tree) {
    if (tree->scene().fingerprint() != scene.fingerprint() || tree->scene().triangle_count() != scene.triangle_count())
      throw UsageError("Tracer: the tree was built for another scene (fingerprint mismatch)");
    options.tree_file = tree->file();  // immutable and shared: no copy of the tree file
  }
  return std::make_shared<Tracer::Impl>(
      Tracer::Impl{scene, make_tracer(accel, scene.soup(), options), accel, accel_info(accel).certified});
}

/// Embree traces a subset of the valid rays (embree_cannot_trace): name the
/// first it cannot by its index in the whole batch, before any block runs
/// (inside a block the tracer knows only the index within that block).
void check_domain(const Tracer::Impl& impl, std::span<const Ray> rays) {
  if (!accel_info(impl.name).embree_domain) return;
  for (std::size_t i = 0; i < rays.size(); ++i)
    if (const char* why = embree_cannot_trace(rays[i]))
      throw UsageError(impl.name + ": ray " + std::to_string(i) + " has " + why +
                       "; such a ray is valid (formats.md): kd, bsp, brute and exact trace it");
}

void check_options(const TraceOptions& o) {
  check_threads(o.threads, "TraceOptions::threads");
  if (o.packet_width != 1 && o.packet_width != 4 && o.packet_width != 8 && o.packet_width != 16)
    throw UsageError("TraceOptions::packet_width must be 1, 4, 8 or 16, not " + std::to_string(o.packet_width));
}

}  // namespace

Tracer::Tracer(const Scene& scene, const Tree& tree, std::string_view mode)
    : impl_(make(scene, accel_for(tree.kind(), mode), &tree)) {}

Tracer Tracer::by_name(const Scene& scene, std::string_view accel) { return Tracer(make(scene, std::string(accel), nullptr)); }
Tracer Tracer::exact(const Scene& scene) { return by_name(scene, "exact"); }
std::vector<std::string> Tracer::accelerators() { return accel_names(); }

std::string Tracer::name() const { return impl().name; }
bool Tracer::certified() const { return impl().certified; }
std::size_t Tracer::memory_bytes() const { return impl().accel->memory_bytes(); }

Hit Tracer::intersect(const Ray& ray) const {
  const IeeeScope ieee;  // the certified bounds assume IEEE arithmetic (fp_env.h); one MXCSR read
  return impl().accel->trace(ray);
}

void Tracer::intersect(std::span<const Ray> rays, std::span<Hit> hits, const TraceOptions& options) const {
  const IeeeScope ieee;  // before check_domain: DAZ would read a subnormal tnear as 0 (fp_env.h)
  check_options(options);
  if (rays.size() != hits.size())
    throw UsageError("intersect: " + std::to_string(rays.size()) + " rays but room for " + std::to_string(hits.size()) +
                     " hits");
  check_domain(impl(), rays);
  api::for_blocks(rays.size(), options.threads, [&](std::size_t b, std::size_t e) {
    impl().accel->trace_batch(rays.subspan(b, e - b), hits.subspan(b, e - b), options.packet_width);
  });
}

bool Tracer::occluded(const Ray& ray) const {
  const IeeeScope ieee;
  return impl().accel->occluded(ray);
}

void Tracer::occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded, const TraceOptions& options) const {
  const IeeeScope ieee;
  check_options(options);
  if (rays.size() != occluded.size())
    throw UsageError("occluded: " + std::to_string(rays.size()) + " rays but room for " +
                     std::to_string(occluded.size()) + " answers");
  check_domain(impl(), rays);
  api::for_blocks(rays.size(), options.threads, [&](std::size_t b, std::size_t e) {
    if (options.packet_width <= 1) {  // single rays: the tracer's own any-hit query (the BVH8 stops at a first hit)
      for (std::size_t i = b; i < e; ++i) occluded[i] = impl().accel->occluded(rays[i]) ? 1 : 0;
      return;
    }
    std::vector<Hit> hits(e - b);
    impl().accel->trace_batch(rays.subspan(b, e - b), hits, options.packet_width);
    for (std::size_t i = b; i < e; ++i) occluded[i] = hits[i - b].hit() ? 1 : 0;
  });
}

}  // namespace bsprt
