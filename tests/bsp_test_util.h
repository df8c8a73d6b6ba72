#pragma once
// Helpers of the BSP traversal tests (test_bsp_traverse.cpp, test_bsp_epsilon.cpp):
// build + flatten a scene, the exact ray/triangle oracle, and the comparison of
// a tracer with brute force that counts lost hits.
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "builder/bsp/bsp_build.h"
#include "builder/bsp/bsp_flatten.h"
#include "bsprt/ray.h"
#include "geometry/core/triangle_soup.h"
#include "robust/degenerate.h"
#include "traverse/brute_force.h"
#include "traverse/bsp/bsp_traverse.h"

namespace bsprt::test {

/// A scene with its exact tree and flattening.
struct BspScene {
  TriangleSoup soup;
  BspTree exact;
  FlatBspTree flat;
};

inline BspScene build_bsp_scene(TriangleSoup soup, const BspConfig& config = {}) {
  BspScene s;
  s.soup = std::move(soup);
  classify_degenerate(s.soup);
  s.exact = build_bsp(s.soup, config);
  s.flat = flatten_bsp(s.soup, s.exact);
  return s;
}

/// Exact oracle: does the exact segment org + t·dir, t in [tnear, tfar] (tnear
/// finite), meet triangle `prim`? CGAL Epeck: exact constructions and predicates.
inline bool exact_hits(const TriangleSoup& soup, const Ray& r, std::uint32_t prim) {
  using K = CGAL::Epeck;
  const auto pt = [](const Vec3f& v) { return K::Point_3(v.x, v.y, v.z); };
  const K::Point_3 o = pt(r.org);
  const K::Vector_3 d(r.dir.x, r.dir.y, r.dir.z);
  const K::Triangle_3 tri(pt(soup.corner(prim, 0)), pt(soup.corner(prim, 1)), pt(soup.corner(prim, 2)));
  const K::Point_3 a = o + d * K::FT(double(r.tnear));
  if (std::isinf(r.tfar)) return CGAL::do_intersect(tri, K::Ray_3(a, d));
  const K::Point_3 b = o + d * K::FT(double(r.tfar));
  if (a == b) return CGAL::do_intersect(tri, a);
  return CGAL::do_intersect(tri, K::Segment_3(a, b));
}

/// Outcome of comparing a tracer with brute force on the same rays.
struct Comparison {
  std::size_t rays = 0, hits = 0, same = 0, ties = 0;
  std::size_t float_only = 0;  ///< brute force hit where the exact ray misses; tracer missed: fine
  std::size_t lost = 0;        ///< brute force hit that the exact ray also hits; tracer missed
  std::size_t farther = 0;     ///< both hit, tracer's t beyond tolerance
  std::size_t impossible = 0;  ///< tracer hit where brute force missed, or t below brute force
  std::string first_failure;
  bool ok() const { return lost == 0 && farther == 0 && impossible == 0; }
};

inline std::string describe(const Ray& r, const Hit& a, const Hit& b) {
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "ray o=(%.9g %.9g %.9g) d=(%.9g %.9g %.9g) [%g %g]: tracer prim %u t=%.9g, brute prim %u t=%.9g",
                r.org.x, r.org.y, r.org.z, r.dir.x, r.dir.y, r.dir.z, r.tnear, r.tfar, a.prim, a.t,
                b.prim, b.t);
  return buf;
}

/// Traces every ray with `tracer` and brute force and classifies the pairs
/// (shared/formats.md "Comparing two hit files"). A tie is a different
/// triangle at t within 1e-5 relative (shared edges and vertices).
inline Comparison compare_with_brute(const TriangleSoup& soup, const Accelerator& tracer,
                                     std::span<const Ray> rays) {
  const BruteForceTracer bf(soup);
  Comparison c;
  for (const Ray& r : rays) {
    const Hit a = tracer.trace(r), b = bf.trace(r);
    ++c.rays;
    c.hits += b.hit();
    std::size_t* bad = nullptr;
    if (a.prim == b.prim) {
      if (a.hit() && a.t != b.t) bad = &c.impossible;
      else ++c.same;
    } else if (a.hit() && b.hit()) {
      if (a.t < b.t) bad = &c.impossible;
      else if (a.t - b.t <= 1e-5f * std::fabs(b.t)) ++c.ties;
      else bad = &c.farther;
    } else if (b.hit()) {
      if (exact_hits(soup, r, b.prim)) bad = &c.lost;
      else ++c.float_only;
    } else {
      bad = &c.impossible;
    }
    if (bad) {
      ++*bad;
      if (c.first_failure.empty()) c.first_failure = describe(r, a, b);
    }
  }
  return c;
}

}  // namespace bsprt::test
