#pragma once
/// \file render.h
/// Ray casting into an image over any Accelerator: primary rays in 16x16 tiles,
/// traced in parallel with oneTBB, packets when asked, eye-light shading.

#include <cstdint>
#include <functional>

#include "apps/image_io.h"
#include "geometry/scenes/camera.h"
#include "geometry/core/triangle_soup.h"
#include "traverse/counters.h"
#include "traverse/accelerator.h"

namespace bsprt {

/// What to render.
struct RenderOptions {
  int width = 800;       ///< image width in pixels (--size)
  int height = 600;      ///< image height in pixels (--size)
  Camera camera;         ///< --vp/--vi/--vu/--fov
  int packet_width = 1;  ///< rays per packet: 1, 4, 8 or 16 (--packets)
};

/// Figures of one render.
struct RenderStats {
  std::uint64_t rays = 0;
  std::uint64_t hits = 0;
  double seconds = 0.0;
  RayCounters counters;  ///< summed over all rays
};

/// Called with (tiles done, tiles total) from worker threads.
using RenderProgress = std::function<void(std::uint64_t, std::uint64_t)>;

/// Ray-casts the scene with eye-light shading (|cos| between the face normal and
/// the ray, so both sides are lit); misses get a sky gradient.
Image render_cast(const Accelerator& tracer, const TriangleSoup& soup, const RenderOptions& options,
                  RenderStats* stats = nullptr, const RenderProgress& progress = {});

}  // namespace bsprt
