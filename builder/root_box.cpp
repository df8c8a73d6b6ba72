#include "builder/root_box.h"

#include <array>
#include <cmath>

#include "bsprt/error.h"
#include "robust/degenerate.h"

namespace bsprt {

void check_box_finite(const std::string& path, const std::string& what, const Box3f& box) {
  // The empty box (+inf, -inf) of a tree over no hittable triangle, as the
  // kd build gives a scene of degenerate triangles only: no ray enters it.
  const Box3f empty;
  if (box.lo == empty.lo && box.hi == empty.hi) return;
  for (int a = 0; a < 3; ++a)
    if (!(std::isfinite(box.lo[a]) && std::isfinite(box.hi[a]) && box.lo[a] <= box.hi[a]))
      throw InputError(path, what + " is not finite, or inverted, on axis " + std::to_string(a));
}

void check_root_box(const std::string& path, const std::string& what, const Box3f& box, const TriangleSoup& soup) {
  check_box_finite(path, what, box);
  for (std::uint32_t t = 0; t < soup.size(); ++t) {
    if (soup.is_degenerate(t)) continue;
    bool inside = true, finite = true;
    for (int k = 0; k < 3; ++k) {
      const Vec3f p = soup.corner(t, k);
      finite = finite && is_finite(p);
      for (int a = 0; a < 3; ++a) inside = inside && box.lo[a] <= p[a] && p[a] <= box.hi[a];
    }
    // Only a triangle outside the box pays for the exact collinearity test.
    const std::array<Vec3f, 3> c = soup.corners(t);
    if (!inside && finite && !is_degenerate_exact(c[0], c[1], c[2]))
      throw InputError(
          path, what + " does not contain triangle " + std::to_string(t) + " (the tree would never find its hits)");
  }
}

}  // namespace bsprt
