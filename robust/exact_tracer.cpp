#include "robust/exact_tracer.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "robust/nearest_float.h"

namespace bsprt {
namespace {

using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;
using Epeck = CGAL::Exact_predicates_exact_constructions_kernel;
using TriangleList = std::vector<Epick::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<Epick, TriangleList::const_iterator>;
using AabbTree = CGAL::AABB_tree<CGAL::AABB_traits<Epick, Primitive>>;
using FT = Epeck::FT;

/// FLT_MAX + half an ulp: an exact t at or beyond it rounds to infinity (robust/nearest_float.h).
constexpr double kFloatOverflow = 0x1.ffffffp127;

Epick::Point_3 to_epick(const Vec3f& p) { return {p.x, p.y, p.z}; }
Epeck::Point_3 to_epeck(const Vec3f& p) { return {p.x, p.y, p.z}; }

/// The direction of `ray` as an Epick vector, scaled by a power of two (the
/// same ray) if needed, such that o + d rounds to nothing in double; nullopt
/// when neither the direction itself nor the one scaled to the origin's
/// magnitude qualifies. Epick's Ray_3 and Line_3 store the point o + d computed
/// in double: when that sum rounds, the query is a slightly rotated ray whose
/// candidate list may miss a triangle the exact ray touches, and when it rounds
/// to o (a direction tiny against the origin) CGAL rejects the ray as
/// degenerate. Each sum is checked with Knuth's TwoSum error term.
std::optional<Epick::Vector_3> exact_candidate_direction(const Ray& ray) {
  const auto scaled = [&](int shift) -> std::optional<Epick::Vector_3> {
    double d[3];
    for (int k = 0; k < 3; ++k) {
      const double o = ray.org[k];
      d[k] = std::ldexp(double(ray.dir[k]), shift);  // exact: doubles span far more than floats
      const double s = o + d[k], bb = s - o, err = (o - (s - bb)) + (d[k] - bb);
      if (err != 0.0) return std::nullopt;
    }
    return Epick::Vector_3(d[0], d[1], d[2]);
  };
  if (auto d = scaled(0)) return d;
  double mo = 0.0, md = 0.0;
  for (int k = 0; k < 3; ++k) {
    mo = std::max(mo, std::fabs(double(ray.org[k])));
    md = std::max(md, std::fabs(double(ray.dir[k])));
  }
  if (mo == 0.0) return std::nullopt;  // unreachable: o = 0 makes every sum exact
  return scaled(std::ilogb(mo) - std::ilogb(md));  // max|d| near max|o|
}

/// Exact ray parameter of point p on the ray o + t d (p is on the ray).
FT param(const Epeck::Point_3& p, const Epeck::Point_3& o, const Epeck::Vector_3& d) {
  return ((p - o) * d) / (d * d);
}

/// A candidate hit: exact t and the exact point.
struct Candidate {
  FT t;
  Epeck::Point_3 p;
};

/// The exact point where the line o + t d meets the triangle, and its t, when
/// t is in [tnear, tfar]. A line lying in the triangle's plane (a segment of
/// overlap) does not hit it: the convention of the watertight test, which every
/// bsprt tracer shares, so the reference measures the same thing.
template <typename Query>
std::optional<Candidate> exact_hit(const Epeck::Triangle_3& tri, const Query& query, const Epeck::Point_3& o,
                                   const Epeck::Vector_3& d, const std::optional<FT>& tnear,
                                   const std::optional<FT>& tfar) {
  // A line parallel to the plane misses, also where it touches the triangle
  // at a single corner or edge point in its plane (CGAL reports a Point_3 then).
  // Regression test "exact reference: a ray in a triangle's plane touching a corner misses".
  const Epeck::Vector_3 normal = CGAL::cross_product(tri[1] - tri[0], tri[2] - tri[0]);
  if (CGAL::scalar_product(normal, d) == 0) return std::nullopt;
  const auto hit = CGAL::intersection(query, tri);
  if (!hit) return std::nullopt;
  const auto* p = boost::get<Epeck::Point_3>(&*hit);
  if (!p) return std::nullopt;
  const FT t = param(*p, o, d);
  if ((tnear && t < *tnear) || (tfar && t > *tfar)) return std::nullopt;
  return Candidate{t, *p};
}

/// Barycentrics (u of v1, v of v2) of point p in triangle (a, b, c), exactly,
/// by Cramer's rule in the projection that drops the normal's largest axis.
std::pair<float, float> barycentrics(const Epeck::Point_3& p, const Epeck::Point_3& a, const Epeck::Point_3& b,
                                     const Epeck::Point_3& c) {
  const Epeck::Vector_3 e1 = b - a, e2 = c - a, w = p - a;
  const Epeck::Vector_3 n = CGAL::cross_product(e1, e2);
  int drop = 0;
  if (CGAL::abs(n.y()) > CGAL::abs(n[drop])) drop = 1;
  if (CGAL::abs(n.z()) > CGAL::abs(n[drop])) drop = 2;
  const int i = (drop + 1) % 3, j = (drop + 2) % 3;
  const FT det = e1[i] * e2[j] - e1[j] * e2[i];
  const FT u = (w[i] * e2[j] - w[j] * e2[i]) / det;
  const FT v = (e1[i] * w[j] - e1[j] * w[i]) / det;
  return {float(CGAL::to_double(u)), float(CGAL::to_double(v))};
}

}  // namespace

struct ExactTracer::Impl {
  const TriangleSoup& soup;
  TriangleList triangles;            // non-degenerate triangles, Epick
  std::vector<std::uint32_t> prim;   // triangles[i] is triangle prim[i]
  AabbTree tree;

  explicit Impl(const TriangleSoup& s) : soup(s) {
    for (std::uint32_t t = 0; t < s.size(); ++t) {
      if (s.is_degenerate(t)) continue;
      const auto [a, b, c] = s.corners(t);
      triangles.emplace_back(to_epick(a), to_epick(b), to_epick(c));
      prim.push_back(t);
    }
    tree.insert(triangles.begin(), triangles.end());
    tree.build();
  }
};

ExactTracer::ExactTracer(const TriangleSoup& soup) : impl_(std::make_unique<Impl>(soup)) {}
ExactTracer::~ExactTracer() = default;

std::size_t ExactTracer::memory_bytes() const {
  return impl_->triangles.size() * (sizeof(Epick::Triangle_3) + sizeof(std::uint32_t)) +
         impl_->tree.size() * 2 * sizeof(CGAL::Bbox_3);
}

void ExactTracer::touched(const Ray& ray, std::vector<std::uint32_t>& prims) const {
  prims.clear();
  if (!is_valid(ray) || impl_->triangles.empty()) return;
  // Candidates from the AABB tree (exact predicates): a ray when the segment
  // starts at or after the origin, else the whole line. When no exact Epick
  // query exists (exact_candidate_direction), every triangle is a candidate:
  // the exact tests decide, only slower.
  std::vector<TriangleList::const_iterator> hits;
  const Epick::Point_3 eo = to_epick(ray.org);
  if (const std::optional<Epick::Vector_3> ed = exact_candidate_direction(ray)) {
    if (ray.tnear >= 0.0f)
      impl_->tree.all_intersected_primitives(Epick::Ray_3(eo, *ed), std::back_inserter(hits));
    else
      impl_->tree.all_intersected_primitives(Epick::Line_3(eo, *ed), std::back_inserter(hits));
    for (const auto& it : hits) prims.push_back(impl_->prim[std::size_t(it - impl_->triangles.cbegin())]);
  } else {
    prims = impl_->prim;
  }
}

bool ExactTracer::on_surface(const Vec3f& p) const {
  if (impl_->triangles.empty() || !is_finite(p)) return false;
  return impl_->tree.do_intersect(to_epick(p));
}

Hit ExactTracer::trace(const Ray& ray, RayCounters* counters) const {
  if (counters) ++counters->rays;
  Hit best;
  if (!is_valid(ray) || impl_->triangles.empty()) return best;
  // No finite t lies in [+inf, +inf] or in [-inf, -inf] (a valid ray has
  // tnear <= tfar, so these are the segments with an infinite bound on the
  // wrong side), and a hit beyond the float range is no hit: such a segment
  // holds none. The bounds below cannot say so, since they drop infinite ends.
  constexpr float kInf = std::numeric_limits<float>::infinity();
  if (ray.tnear == kInf || ray.tfar == -kInf) return best;
  std::vector<std::uint32_t> candidates;
  touched(ray, candidates);
  if (candidates.empty()) return best;

  const Epeck::Point_3 o = to_epeck(ray.org);
  const Epeck::Vector_3 d(ray.dir.x, ray.dir.y, ray.dir.z);
  const Epeck::Ray_3 exact_ray(o, d);
  const Epeck::Line_3 exact_line(o, d);
  // An infinite bound is no bound (an FT cannot hold one: CGAL asserts finiteness).
  const std::optional<FT> tnear = std::isfinite(ray.tnear) ? std::optional<FT>(FT(ray.tnear)) : std::nullopt;
  const std::optional<FT> tfar = std::isfinite(ray.tfar) ? std::optional<FT>(FT(ray.tfar)) : std::nullopt;
  std::optional<FT> best_t;
  std::optional<Epeck::Point_3> best_p;
  std::uint32_t best_prim = kNoHit;
  for (const std::uint32_t t : candidates) {
    if (counters) ++counters->triangle_tests;
    const auto [a, b, c] = impl_->soup.corners(t);
    const Epeck::Triangle_3 tri(to_epeck(a), to_epeck(b), to_epeck(c));
    const std::optional<Candidate> cand = ray.tnear >= 0.0f ? exact_hit(tri, exact_ray, o, d, tnear, tfar)
                                                            : exact_hit(tri, exact_line, o, d, tnear, tfar);
    if (!cand) continue;
    // A hit beyond the float range (its t rounds to +-inf) is not a hit, in every
    // mode (docs/exact-leaf-test.md, "Hits beyond the float range"); with
    // tnear = -inf a farther, finite hit can then still be the nearest.
    if (cand->t <= FT(-kFloatOverflow) || cand->t >= FT(kFloatOverflow)) continue;
    if (!best_t || cand->t < *best_t || (cand->t == *best_t && t < best_prim)) {
      best_t = cand->t, best_p = cand->p, best_prim = t;
    }
  }
  if (!best_t) return best;
  const auto [a, b, c] = impl_->soup.corners(best_prim);
  const auto [u, v] = barycentrics(*best_p, to_epeck(a), to_epeck(b), to_epeck(c));
  best.t = nearest_float(*best_t);
  best.prim = best_prim;
  best.u = u;
  best.v = v;
  return best;
}

}  // namespace bsprt
