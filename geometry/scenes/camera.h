#pragma once
/// \file camera.h
/// A pinhole camera with Embree-tutorial parameters (--vp, --vi, --vu, --fov),
/// and primary-ray generation shared by the renderer and `bsprt gen-rays`.

#include <string>

#include "bsprt/ray.h"
#include "bsprt/vec3.h"

namespace bsprt {

/// Pinhole camera: position, look-at point, up vector, vertical field of view.
struct Camera {
  Vec3f vp{0, 0, -5};  ///< eye position (--vp)
  Vec3f vi{0, 0, 0};   ///< point looked at (--vi)
  Vec3f vu{0, 1, 0};   ///< up direction (--vu)
  float fov = 60.0f;   ///< vertical field of view in degrees (--fov)
};

/// What makes `cam` unusable, or "" when it is fine: a non-finite field, vp
/// and vi the same point, vu zero or parallel to the view direction, fov not
/// in (0, 180) degrees. Camera files and the --vp/--vi/--vu/--fov options are
/// checked with it, so neither can render a black image from a camera that
/// looks nowhere.
std::string camera_problem(const Camera& cam);

/// Precomputed image-plane basis for generating primary rays quickly.
class CameraRays {
 public:
  CameraRays(const Camera& cam, int width, int height);
  /// The ray through pixel (x, y) at sub-pixel offset (sx, sy) in [0,1)
  /// (0.5, 0.5 = pixel centre); y = 0 is the top row. Direction not normalized.
  Ray ray(int x, int y, float sx = 0.5f, float sy = 0.5f) const;

 private:
  Vec3f org_, corner_, du_, dv_;
};

/// A camera that frames `bounds` from the front (-z looking toward +z,
/// slightly above), at a distance that fits the box in the field of view.
Camera frame_bounds(const Box3f& bounds, float fov = 45.0f);

}  // namespace bsprt
