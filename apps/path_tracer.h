#pragma once
/// \file path_tracer.h
/// A small path tracer over any Accelerator: diffuse surfaces, a rectangular area
/// light with next-event estimation plus a sky, stratified pixel samples, and
/// secondary rays spawned with pbrt-v4's error-bound offsets (ray_offset.h).
/// Paths are traced as wavefronts per 16x16 tile, bounce by bounce, so each
/// bounce's rays are traced in one batch and timed (Mrays/s by bounce, as
/// Ize et al. report for path tracing). Deterministic for a seed: every pixel
/// sample has its own random stream, so images do not depend on threads.

#include <cstdint>
#include <vector>

#include "apps/image_io.h"
#include "apps/render.h"
#include "geometry/scenes/camera.h"
#include "geometry/core/triangle_soup.h"
#include "traverse/accelerator.h"
#include "traverse/counters.h"

namespace bsprt {

/// Path-tracing settings.
struct PathOptions {
  int width = 800;            ///< image width (--size)
  int height = 600;           ///< image height (--size)
  Camera camera;              ///< --vp/--vi/--vu/--fov
  int spp = 16;               ///< samples per pixel (--spp), stratified in the pixel
  int bounces = 3;            ///< indirect bounces after the first hit (--bounces; 0 = direct light only)
  std::uint64_t seed = 1;     ///< random seed (--seed)
  float albedo = 0.7f;        ///< diffuse reflectance of every surface
  int packet_width = 1;       ///< packets for camera rays (--packets); later bounces use single rays
  bool count = false;         ///< count node visits and triangle tests per bounce (--stats; slows the timed trace)
};

/// Figures of a path-traced render.
struct PathStats {
  std::uint64_t rays = 0;                      ///< all rays: camera, bounce and shadow rays
  std::vector<std::uint64_t> rays_by_bounce;   ///< [0] camera rays, [k] rays of bounce k (incl. shadow rays)
  std::vector<double> trace_seconds_by_bounce; ///< summed tracing time over threads, per bounce
  std::vector<RayCounters> counters_by_bounce; ///< work per bounce (PathOptions::count; else all zero)
  std::uint64_t nan_pixels = 0;                ///< pixels whose estimate was not finite (reported, set to 0)
  double seconds = 0.0;                        ///< wall time
};

/// Path-traces the scene; `progress` gets (tiles done, tiles total).
Image render_path(const Accelerator& tracer, const TriangleSoup& soup, const PathOptions& options,
                  PathStats* stats = nullptr, const RenderProgress& progress = {});

}  // namespace bsprt
