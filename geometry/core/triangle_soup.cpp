/// \file triangle_soup.cpp
/// Bounds, counts and concatenation of triangle soups.

#include "geometry/core/triangle_soup.h"

#include <algorithm>
#include <limits>

#include "bsprt/error.h"

namespace bsprt {

Box3f TriangleSoup::bounds() const {
  Box3f box;
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    if (is_degenerate(t)) continue;
    for (int k = 0; k < 3; ++k) box.extend(corner(t, k));
  }
  return box;
}

std::size_t TriangleSoup::unreferenced_vertex_count() const {
  std::vector<std::uint8_t> used(vertices.size(), 0);
  for (const TriIndices& t : triangles)
    for (std::uint32_t v : t) used[v] = 1;
  return static_cast<std::size_t>(std::count(used.begin(), used.end(), std::uint8_t{0}));
}

std::size_t TriangleSoup::degenerate_count() const {
  return static_cast<std::size_t>(std::count_if(degenerate.begin(), degenerate.end(), [](std::uint8_t d) { return d != 0; }));
}

void append(TriangleSoup& a, const TriangleSoup& b) {
  if (a.vertices.size() + b.vertices.size() > std::numeric_limits<std::uint32_t>::max())
    throw UsageError("append: more than 2^32-1 vertices");
  const auto offset = static_cast<std::uint32_t>(a.vertices.size());
  // Keep `degenerate` parallel to `triangles` when either side has flags.
  const bool flags = !a.degenerate.empty() || !b.degenerate.empty();
  if (flags) a.degenerate.resize(a.triangles.size(), 0);
  a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
  a.triangles.reserve(a.triangles.size() + b.triangles.size());
  for (const TriIndices& t : b.triangles) a.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  if (flags) {
    if (b.degenerate.empty())
      a.degenerate.resize(a.triangles.size(), 0);
    else
      a.degenerate.insert(a.degenerate.end(), b.degenerate.begin(), b.degenerate.end());
  }
}

TriangleSoup with_reversed_copies(const TriangleSoup& s) {
  if (s.triangles.size() > std::numeric_limits<std::uint32_t>::max() / 2)
    throw UsageError("with_reversed_copies: more than 2^31-1 triangles");
  TriangleSoup out = s;
  out.triangles.reserve(2 * s.triangles.size());
  for (const TriIndices& t : s.triangles) out.triangles.push_back({t[0], t[2], t[1]});
  if (!s.degenerate.empty()) out.degenerate.insert(out.degenerate.end(), s.degenerate.begin(), s.degenerate.end());
  return out;
}

}  // namespace bsprt
