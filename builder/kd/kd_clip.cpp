#include "builder/kd/kd_clip.h"

#include <cmath>
#include <limits>

namespace bsprt {
namespace {

/// A polygon vertex during clipping; `exact` when it is an input corner.
struct ClipVertex {
  Vec3d p;
  bool exact;
};

/// A convex polygon of at most 3 + 6 vertices.
struct ClipPolygon {
  std::array<ClipVertex, 12> v;
  int n = 0;
};

/// Keeps the part of `in` with sign * (x_k - c) <= 0, where c already includes
/// the outward margin. Kept/dropped is decided by exact comparisons of the
/// stored doubles; new vertices lie on the plane (coordinate k set to c).
void clip_plane(const ClipPolygon& in, int k, double c, double sign, ClipPolygon& out) {
  out.n = 0;
  for (int i = 0; i < in.n; ++i) {
    const ClipVertex& a = in.v[i];
    const ClipVertex& b = in.v[(i + 1) % in.n];
    const double da = sign * (a.p[k] - c), db = sign * (b.p[k] - c);
    if (da <= 0) out.v[out.n++] = a;
    if ((da <= 0) != (db <= 0)) {
      // a inside, b outside or vice versa: t in [0, 1] by monotone rounding.
      const double t = (c - a.p[k]) / (b.p[k] - a.p[k]);
      ClipVertex q{a.p + (b.p - a.p) * t, false};
      q.p[k] = c;
      out.v[out.n++] = q;
    }
  }
}

/// Largest float <= x (x finite).
float round_down(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}
/// Smallest float >= x (x finite).
float round_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

double max_abs(const std::array<Vec3f, 3>& tri, const Box3f& box) {
  double s = 0;
  for (int k = 0; k < 3; ++k) {
    for (const Vec3f& p : tri) s = std::max(s, double(std::abs(p[k])));
    s = std::max({s, double(std::abs(box.lo[k])), double(std::abs(box.hi[k]))});
  }
  return s;
}

}  // namespace

bool clip_triangle_bounds(const std::array<Vec3f, 3>& tri, const Box3f& box, Box3f& out) {
  Box3f limit = box;  // box ∩ bounds(triangle): contains the exact set
  Box3f tb;
  for (const Vec3f& p : tri) tb.extend(p);
  limit.lo = max(limit.lo, tb.lo);
  limit.hi = min(limit.hi, tb.hi);
  if (limit.empty()) return false;
  // Fully inside the box: nothing to clip, the corners are exact.
  if (tb.lo.x >= box.lo.x && tb.lo.y >= box.lo.y && tb.lo.z >= box.lo.z &&
      tb.hi.x <= box.hi.x && tb.hi.y <= box.hi.y && tb.hi.z <= box.hi.z) {
    out = tb;
    return true;
  }
  const double scale = std::max(max_abs(tri, box), std::numeric_limits<double>::min());
  const double delta = std::ldexp(scale, -44);
  const double margin = 16 * delta;  // > 6 chained interpolation errors
  ClipPolygon a, b;
  for (int i = 0; i < 3; ++i) a.v[i] = {Vec3d(tri[i]), true};
  a.n = 3;
  for (int k = 0; k < 3 && a.n > 0; ++k) {
    clip_plane(a, k, double(box.lo[k]) - margin, -1.0, b);
    if (b.n == 0) return false;
    clip_plane(b, k, double(box.hi[k]) + margin, 1.0, a);
  }
  if (a.n == 0) return false;
  Box3d bd;
  for (int i = 0; i < a.n; ++i) {
    const ClipVertex& v = a.v[i];
    const double w = v.exact ? 0.0 : margin;
    bd.extend(Vec3d(v.p.x - w, v.p.y - w, v.p.z - w));
    bd.extend(Vec3d(v.p.x + w, v.p.y + w, v.p.z + w));
  }
  for (int k = 0; k < 3; ++k) {
    out.lo[k] = std::max(round_down(bd.lo[k]), limit.lo[k]);
    out.hi[k] = std::min(round_up(bd.hi[k]), limit.hi[k]);
    if (out.lo[k] > out.hi[k]) return false;
  }
  return true;
}

}  // namespace bsprt
