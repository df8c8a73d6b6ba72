/// \file scene.cpp
/// bsprt::Scene (include/bsprt/scene.h): arrays or files to the internal soup,
/// with the CLI's checks and counts.
#include "bsprt/scene.h"

#include <string>

#include "builder/tree_file.h"
#include "geometry/core/fp_env.h"
#include "geometry/core/triangle_soup.h"
#include "geometry/io/load_mesh.h"
#include "geometry/scenes/default_scene.h"
#include "robust/degenerate.h"

namespace bsprt {

struct Scene::Impl {
  TriangleSoup soup;
  SceneSummary summary;
  std::uint64_t fingerprint = 0;
};

Scene::Scene(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

const Scene::Impl& Scene::impl() const {
  if (!impl_)
    throw UsageError("bsprt::Scene used after it was moved from (only assigning to it or destroying it is "
                     "allowed)");
  return *impl_;
}

Scene Scene::from_arrays(std::span<const float> vertices, std::span<const std::uint32_t> indices,
                         const SceneOptions& options) {
  if (vertices.size() % 3 != 0)
    throw UsageError("vertices: " + std::to_string(vertices.size()) + " floats, not a multiple of 3 (x, y, z per vertex)");
  if (indices.size() % 3 != 0)
    throw UsageError("indices: " + std::to_string(indices.size()) + " values, not a multiple of 3 (3 per triangle)");
  if (indices.empty()) throw UsageError("indices: the scene has no triangles");
  const IeeeScope ieee;  // classify_degenerate's exact filters assume IEEE arithmetic (fp_env.h)
  auto impl = std::make_shared<Impl>();
  TriangleSoup& soup = impl->soup;
  const std::size_t nv = vertices.size() / 3;
  if (nv > 0xFFFFFFFFull) throw UsageError("vertices: more than 2^32 - 1 vertices");
  soup.vertices.resize(nv);
  for (std::size_t i = 0; i < nv; ++i) soup.vertices[i] = {vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]};
  soup.triangles.resize(indices.size() / 3);
  std::size_t nonfinite = 0;
  for (std::size_t t = 0; t < soup.triangles.size(); ++t) {
    bool finite = true;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = indices[3 * t + std::size_t(k)];
      if (v >= nv)
        throw UsageError("indices: triangle " + std::to_string(t) + " corner " + std::to_string(k) + " is vertex " +
                         std::to_string(v) + ", but there are " + std::to_string(nv) + " vertices");
      soup.triangles[t][std::size_t(k)] = v;
      if (!is_finite(soup.vertices[v])) {
        if (!options.allow_nonfinite)
          throw UsageError("vertices: vertex " + std::to_string(v) + " is not finite and triangle " + std::to_string(t) +
                           " uses it; allow_nonfinite keeps such triangles as never-hit degenerates");
        finite = false;
      }
    }
    nonfinite += !finite;
  }
  const std::size_t degenerate = classify_degenerate(soup);
  impl->summary = {"arrays", nv, soup.unreferenced_vertex_count(), soup.size(), degenerate, nonfinite};
  impl->fingerprint = scene_fingerprint(soup);
  return Scene(std::move(impl));
}

Scene Scene::load(const std::string& path, const SceneOptions& options) {
  if (path == "default") return default_scene();
  const IeeeScope ieee;
  auto impl = std::make_shared<Impl>();
  LoadOptions lo;
  lo.allow_nonfinite = options.allow_nonfinite;
  LoadReport report;
  impl->soup = load_mesh(path, lo, &report);
  impl->summary = {path, report.vertices, report.unreferenced_vertices, report.triangles, report.degenerate,
                   report.nonfinite_triangles};
  impl->fingerprint = scene_fingerprint(impl->soup);
  return Scene(std::move(impl));
}

Scene Scene::default_scene() {
  const IeeeScope ieee;
  auto impl = std::make_shared<Impl>();
  impl->soup = make_default_scene();
  impl->summary = {"default", impl->soup.vertices.size(), impl->soup.unreferenced_vertex_count(), impl->soup.size(),
                   impl->soup.degenerate_count(), 0};
  impl->fingerprint = scene_fingerprint(impl->soup);
  return Scene(std::move(impl));
}

std::size_t Scene::triangle_count() const { return impl().soup.size(); }
std::size_t Scene::vertex_count() const { return impl().soup.vertices.size(); }
const SceneSummary& Scene::summary() const { return impl().summary; }
Box3f Scene::bounds() const {
  const IeeeScope ieee;
  return impl().soup.bounds();
}
std::uint64_t Scene::fingerprint() const { return impl().fingerprint; }
const TriangleSoup& Scene::soup() const { return impl().soup; }

Vec3f Scene::corner(std::size_t t, int k) const {
  if (t >= impl().soup.size() || k < 0 || k > 2)
    throw UsageError("corner(" + std::to_string(t) + ", " + std::to_string(k) + "): the scene has " +
                     std::to_string(impl().soup.size()) + " triangles of 3 corners");
  return impl().soup.corner(std::uint32_t(t), k);
}

}  // namespace bsprt
