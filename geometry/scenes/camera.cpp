#include "geometry/scenes/camera.h"

#include <cmath>
#include <numbers>

#include "bsprt/error.h"

namespace bsprt {

namespace {

/// The camera's unit basis, made in double: for finite float fields nothing
/// overflows or underflows there (vi - vp of points at +-3e38, a 1e30 up
/// vector: in float these overflowed and gave NaN or identical rays; a review
/// of 2026-12-07). Zero vectors when vp == vi or vu is parallel to the view.
struct Basis {
  Vec3d fwd, right, up;
  double view_len2 = 0, side_len2 = 0;
};

Basis camera_basis(const Camera& cam) {
  Basis b;
  const Vec3d view = Vec3d(cam.vi) - Vec3d(cam.vp);
  b.view_len2 = dot(view, view);
  if (b.view_len2 == 0) return b;
  b.fwd = normalize(view);
  const Vec3d side = cross(b.fwd, Vec3d(cam.vu));
  b.side_len2 = dot(side, side);
  if (b.side_len2 == 0) return b;
  b.right = normalize(side);
  b.up = cross(b.right, b.fwd);
  return b;
}

}  // namespace

std::string camera_problem(const Camera& cam) {
  if (!is_finite(cam.vp)) return "vp (the position) is not finite";
  if (!is_finite(cam.vi)) return "vi (the point looked at) is not finite";
  if (!is_finite(cam.vu)) return "vu (the up vector) is not finite";
  if (!(cam.fov > 0.0f && cam.fov < 180.0f)) return "fov " + std::to_string(cam.fov) + " is not in (0, 180) degrees";
  const Basis b = camera_basis(cam);
  if (b.view_len2 == 0) return "vp and vi are the same point";
  if (b.side_len2 == 0) return "vu is parallel to the view direction (or zero)";
  return "";
}

CameraRays::CameraRays(const Camera& cam, int width, int height) : org_(cam.vp) {
  const Basis b = camera_basis(cam);
  const Vec3f fwd(b.fwd), right(b.right), up(b.up);
  const float half_h = std::tan(cam.fov * std::numbers::pi_v<float> / 360.0f);
  const float half_w = half_h * float(width) / float(height);
  du_ = right * (2.0f * half_w / float(width));
  dv_ = up * (-2.0f * half_h / float(height));
  corner_ = fwd - right * half_w + up * half_h;
}

Ray CameraRays::ray(int x, int y, float sx, float sy) const {
  Ray r;
  r.org = org_;
  r.dir = corner_ + du_ * (float(x) + sx) + dv_ * (float(y) + sy);
  return r;
}

Camera frame_bounds(const Box3f& bounds, float fov) {
  if (!(bounds.lo.x <= bounds.hi.x && bounds.lo.y <= bounds.hi.y && bounds.lo.z <= bounds.hi.z))
    throw UsageError("the scene has no non-degenerate triangle, so there is nothing to frame: give a camera "
                     "(render: --camera, or --vp and --vi; gen-rays: --camera; bench: --cameras)");
  Camera cam;
  const Vec3f c = bounds.center();
  const float radius = 0.5f * length(bounds.diagonal());
  const float dist = radius / std::sin(fov * std::numbers::pi_v<float> / 360.0f);
  const Vec3f view = normalize(Vec3f{0.35f, 0.45f, -1.0f});
  cam.vi = c;
  cam.vp = c + view * dist;
  cam.vu = {0, 1, 0};
  cam.fov = fov;
  if (const std::string problem = camera_problem(cam); !problem.empty())
    throw UsageError("cannot frame the scene (its bounds are too large for a float camera: " + problem +
                     "): give a camera (render: --camera, or --vp and --vi; gen-rays: --camera; bench: --cameras)");
  return cam;
}

}  // namespace bsprt
