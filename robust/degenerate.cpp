/// \file degenerate.cpp
/// Exact degeneracy classification with CGAL's filtered predicates.

#include "robust/degenerate.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

namespace bsprt {
namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

// Every float is exactly a double, so the predicate sees the input exactly.
Kernel::Point_3 to_point(const Vec3f& p) {
  return {static_cast<double>(p.x), static_cast<double>(p.y), static_cast<double>(p.z)};
}
}  // namespace

bool is_degenerate_exact(const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  // Non-finite coordinates have no place in exact arithmetic: never hit.
  if (!is_finite(a) || !is_finite(b) || !is_finite(c)) return true;
  // collinear() is true for coincident points too; filtered, so exact
  // arithmetic only runs when the double evaluation cannot decide.
  return CGAL::collinear(to_point(a), to_point(b), to_point(c));
}

std::size_t classify_degenerate(TriangleSoup& soup) {
  soup.degenerate.assign(soup.triangles.size(), 0);
  std::size_t count = 0;
  for (std::size_t t = 0; t < soup.triangles.size(); ++t) {
    const auto& i = soup.triangles[t];
    const bool d = is_degenerate_exact(soup.vertices[i[0]], soup.vertices[i[1]], soup.vertices[i[2]]);
    soup.degenerate[t] = d ? 1 : 0;
    count += d ? 1 : 0;
  }
  return count;
}

}  // namespace bsprt
