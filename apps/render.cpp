#include "apps/render.h"

#include <tbb/blocked_range2d.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <vector>

#include "geometry/core/fp_env.h"

namespace bsprt {
namespace {

constexpr int kTile = 16;

/// Eye-light shade of a hit: warm grey scaled by |cos(normal, ray)|.
std::array<float, 3> shade(const TriangleSoup& soup, const Ray& ray, const Hit& hit) {
  if (!hit.hit()) {
    const float up = 0.5f + 0.5f * normalize(ray.dir).y;
    return {0.25f + 0.35f * up, 0.3f + 0.4f * up, 0.45f + 0.45f * up};
  }
  const Vec3f n = soup.unit_normal(hit.prim);
  const float cosine = std::abs(dot(n, normalize(ray.dir)));
  const float k = 0.1f + 0.9f * cosine;
  return {0.85f * k, 0.78f * k, 0.68f * k};
}

struct TileStats {
  std::uint64_t hits = 0;
  RayCounters counters;
};

}  // namespace

Image render_cast(const Accelerator& tracer, const TriangleSoup& soup, const RenderOptions& options,
                  RenderStats* stats, const RenderProgress& progress) {
  IeeeTasks ieee;  // IEEE arithmetic here and in every task, camera set-up included (geometry/core/fp_env.h)
  const auto start = std::chrono::steady_clock::now();
  Image image(options.width, options.height);
  const CameraRays camera(options.camera, options.width, options.height);
  const int tiles_x = (options.width + kTile - 1) / kTile;
  const int tiles_y = (options.height + kTile - 1) / kTile;
  const std::uint64_t tiles_total = std::uint64_t(tiles_x) * std::uint64_t(tiles_y);
  std::atomic<std::uint64_t> tiles_done{0};
  tbb::combinable<TileStats> per_thread;

  tbb::parallel_for(tbb::blocked_range2d<int>(0, tiles_y, 1, 0, tiles_x, 1), [&](const auto& range) {
    std::vector<Ray> rays;
    std::vector<Hit> hits;
    TileStats& local = per_thread.local();
    for (int ty = range.rows().begin(); ty < range.rows().end(); ++ty)
      for (int tx = range.cols().begin(); tx < range.cols().end(); ++tx) {
        const int x0 = tx * kTile, y0 = ty * kTile;
        const int x1 = std::min(x0 + kTile, options.width), y1 = std::min(y0 + kTile, options.height);
        rays.clear();
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x) rays.push_back(camera.ray(x, y));
        hits.resize(rays.size());
        tracer.trace_batch(rays, hits, options.packet_width, stats ? &local.counters : nullptr);
        std::size_t i = 0;
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x, ++i) {
            const auto rgb = shade(soup, rays[i], hits[i]);
            float* p = image.pixel(x, y);
            p[0] = rgb[0], p[1] = rgb[1], p[2] = rgb[2];
            local.hits += hits[i].hit();
          }
        const std::uint64_t done = tiles_done.fetch_add(1) + 1;
        if (progress) progress(done, tiles_total);
      }
  }, ieee.context());

  if (stats) {
    *stats = {};
    stats->rays = std::uint64_t(options.width) * std::uint64_t(options.height);
    per_thread.combine_each([&](const TileStats& t) {
      stats->hits += t.hits;
      stats->counters += t.counters;
    });
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return image;
}

}  // namespace bsprt
