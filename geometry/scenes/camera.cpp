#include "geometry/scenes/camera.h"

#include <cmath>
#include <numbers>

#include "bsprt/error.h"

namespace bsprt {

std::string camera_problem(const Camera& cam) {
  if (!is_finite(cam.vp)) return "vp (the position) is not finite";
  if (!is_finite(cam.vi)) return "vi (the point looked at) is not finite";
  if (!is_finite(cam.vu)) return "vu (the up vector) is not finite";
  if (!(cam.fov > 0.0f && cam.fov < 180.0f)) return "fov " + std::to_string(cam.fov) + " is not in (0, 180) degrees";
  const Vec3f view = cam.vi - cam.vp;
  if (dot(view, view) == 0.0f) return "vp and vi are the same point";
  const Vec3f side = cross(view, cam.vu);
  if (dot(side, side) == 0.0f) return "vu is parallel to the view direction (or zero)";
  return "";
}

CameraRays::CameraRays(const Camera& cam, int width, int height) : org_(cam.vp) {
  const Vec3f fwd = normalize(cam.vi - cam.vp);
  const Vec3f right = normalize(cross(fwd, cam.vu));
  const Vec3f up = cross(right, fwd);
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
                     "(--camera, or --vp and --vi)");
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
                     "): give a camera (--camera, or --vp and --vi)");
  return cam;
}

}  // namespace bsprt
