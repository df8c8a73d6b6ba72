/// \file query.cpp
/// bsprt::MeshQuery (include/bsprt/query.h): robust/inside_query.h over a
/// Scene, the code `bsprt inside` and `bsprt trace --all-hits` run.
#include "bsprt/query.h"

#include <iomanip>
#include <sstream>
#include <string>

#include "api/blocks.h"
#include "geometry/core/fp_env.h"
#include "robust/inside_query.h"

namespace bsprt {

struct MeshQuery::Impl {
  Scene scene;  // keeps the soup the query points into alive
  InsideQuery query;
  explicit Impl(const Scene& s) : scene(s), query(scene.soup()) {}
};

MeshQuery::MeshQuery(const Scene& scene) {
  const IeeeScope ieee;  // the AABB tree's exact predicates assume IEEE arithmetic
  impl_ = std::make_shared<const Impl>(scene);
}

const MeshQuery::Impl& MeshQuery::impl() const {
  if (!impl_)
    throw UsageError("bsprt::MeshQuery used after it was moved from (only assigning to it or destroying it is "
                     "allowed)");
  return *impl_;
}

std::size_t MeshQuery::open_or_inconsistent_edges() const {
  return bsprt::open_or_inconsistent_edges(impl().scene.soup());
}

namespace {

void check_point(const Vec3f& p, std::size_t index, bool in_span) {
  if (is_finite(p)) return;
  std::ostringstream s;
  s << std::setprecision(9) << (in_span ? "sides: point " + std::to_string(index) : std::string("side: the point"))
    << " has a NaN or infinite coordinate (" << p.x << ", " << p.y << ", " << p.z
    << "); inside and outside are defined for finite points only";
  throw UsageError(s.str());
}

Crossing public_crossing(std::uint64_t ray, const CertifiedIntersector::Crossing& x) {
  return Crossing{ray, x.prim, x.t, std::int32_t(x.side)};
}

}  // namespace

PointSide MeshQuery::side(const Vec3f& p) const {
  const IeeeScope ieee;
  check_point(p, 0, false);
  return impl().query.side(p);
}

void MeshQuery::sides(std::span<const Vec3f> points, std::span<PointSide> sides, const QueryOptions& options) const {
  const IeeeScope ieee;
  check_threads(options.threads, "QueryOptions::threads");
  if (points.size() != sides.size())
    throw UsageError("sides: " + std::to_string(points.size()) + " points but room for " +
                     std::to_string(sides.size()) + " answers");
  for (std::size_t i = 0; i < points.size(); ++i) check_point(points[i], i, true);
  const InsideQuery& q = impl().query;
  api::for_blocks(points.size(), options.threads, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) sides[i] = q.side(points[i]);
  });
}

std::vector<Crossing> MeshQuery::crossings(const Ray& ray) const {
  const IeeeScope ieee;
  std::vector<std::uint32_t> candidates;
  std::vector<CertifiedIntersector::Crossing> xs;
  impl().query.crossings(ray, candidates, xs);
  std::vector<Crossing> out;
  out.reserve(xs.size());
  for (const auto& x : xs) out.push_back(public_crossing(0, x));
  return out;
}

std::vector<Crossing> MeshQuery::all_hits(std::span<const Ray> rays, const QueryOptions& options) const {
  const IeeeScope ieee;
  check_threads(options.threads, "QueryOptions::threads");
  const InsideQuery& q = impl().query;
  std::vector<std::vector<CertifiedIntersector::Crossing>> per_ray(rays.size());
  api::for_blocks(rays.size(), options.threads, [&](std::size_t b, std::size_t e) {
    std::vector<std::uint32_t> candidates;
    for (std::size_t i = b; i < e; ++i) q.crossings(rays[i], candidates, per_ray[i]);
  });
  std::size_t total = 0;
  for (const auto& xs : per_ray) total += xs.size();
  std::vector<Crossing> out;
  out.reserve(total);
  for (std::size_t i = 0; i < rays.size(); ++i)
    for (const auto& x : per_ray[i]) out.push_back(public_crossing(i, x));
  return out;
}

}  // namespace bsprt
