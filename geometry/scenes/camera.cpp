#include "geometry/scenes/camera.h"

#include <cmath>
#include <numbers>

namespace bsprt {

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
  Camera cam;
  const Vec3f c = bounds.center();
  const float radius = 0.5f * length(bounds.diagonal());
  const float dist = radius / std::sin(fov * std::numbers::pi_v<float> / 360.0f);
  const Vec3f view = normalize(Vec3f{0.35f, 0.45f, -1.0f});
  cam.vi = c;
  cam.vp = c + view * dist;
  cam.vu = {0, 1, 0};
  cam.fov = fov;
  return cam;
}

}  // namespace bsprt
