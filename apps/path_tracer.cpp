#include "apps/path_tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <numbers>

#include "apps/ray_offset.h"
#include "geometry/core/fp_env.h"

namespace bsprt {
namespace {

constexpr int kTile = 16;
constexpr float kPi = std::numbers::pi_v<float>;

/// A counter-based random stream (PCG hash of seed, pixel, sample, draw), so
/// results never depend on scheduling.
class Sampler {
 public:
  Sampler(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample)
      : state_(hash(seed * 0x9E3779B97F4A7C15ull ^ hash(pixel * 0x100000001B3ull + sample))) {}
  float next() {
    state_ = hash(state_ + 0x9E3779B97F4A7C15ull);
    return float(state_ >> 40) * 0x1.0p-24f;
  }

 private:
  static std::uint64_t hash(std::uint64_t x) {  // splitmix64 finaliser
    x ^= x >> 30, x *= 0xBF58476D1CE4E5B9ull;
    x ^= x >> 27, x *= 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  }
  std::uint64_t state_;
};

/// The rectangular area light, facing down, just under the top of the scene.
struct AreaLight {
  Vec3f corner, edge_u, edge_v, normal{0, -1, 0};
  float radiance = 0, area = 0;
  explicit AreaLight(const Box3f& b) {
    const Vec3f d = b.diagonal(), c = b.center();
    const float side = 0.35f * std::max(std::min(d.x, d.z), 0.2f * std::max(d.x, d.z));
    const float y = b.hi.y - 0.002f * d.y;
    corner = {c.x - side / 2, y, c.z - side / 2};
    edge_u = {side, 0, 0};
    edge_v = {0, 0, side};
    area = side * side;
    const float h = std::max(d.y, 0.25f * length(d));
    radiance = 2.5f * h * h / area;
  }
};

/// Sky radiance seen in direction d (a soft gradient; it also lights paths).
Vec3f sky(const Vec3f& d) {
  const float up = 0.5f + 0.5f * normalize(d).y;
  return Vec3f{0.20f + 0.15f * up, 0.25f + 0.2f * up, 0.35f + 0.3f * up} * 0.6f;
}

/// Cosine-weighted direction around n.
Vec3f sample_cosine(const Vec3f& n, float r1, float r2) {
  const Vec3f t = normalize(std::abs(n.x) > 0.5f ? cross(n, Vec3f{0, 1, 0}) : cross(n, Vec3f{1, 0, 0}));
  const Vec3f b = cross(n, t);
  const float r = std::sqrt(r1), phi = 2 * kPi * r2;
  return t * (r * std::cos(phi)) + b * (r * std::sin(phi)) + n * std::sqrt(std::max(0.0f, 1 - r1));
}

struct PathState {
  Vec3f throughput{1, 1, 1};
  Vec3f radiance{0, 0, 0};
  bool alive = true;
};

struct ThreadStats {
  std::vector<std::uint64_t> rays;
  std::vector<double> seconds;
  std::vector<RayCounters> counters;  ///< per bounce, when counting
  bool count = false;
  RayCounters* counters_of(int bounce) { return count ? &counters[std::size_t(bounce)] : nullptr; }
};

/// Traces `rays` into `hits` and books the time and count under `bounce`.
void trace_timed(const Accelerator& tracer, const std::vector<Ray>& rays, std::vector<Hit>& hits, int packet,
                 ThreadStats& ts, int bounce) {
  hits.resize(rays.size());
  const auto t0 = std::chrono::steady_clock::now();
  tracer.trace_batch(rays, hits, packet, ts.counters_of(bounce));
  ts.seconds[bounce] += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ts.rays[bounce] += rays.size();
}

/// Shadow rays: the tracer's any-hit query (Accelerator::occluded), ray by ray;
/// books the time and count under `bounce` as trace_timed does.
void occluded_timed(const Accelerator& tracer, const std::vector<Ray>& rays, std::vector<char>& blocked,
                    ThreadStats& ts, int bounce) {
  blocked.resize(rays.size());
  const auto t0 = std::chrono::steady_clock::now();
  RayCounters* const c = ts.counters_of(bounce);
  for (std::size_t i = 0; i < rays.size(); ++i) blocked[i] = tracer.occluded(rays[i], c) ? 1 : 0;
  ts.seconds[bounce] += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ts.rays[bounce] += rays.size();
}

}  // namespace

namespace {

/// Everything one tile needs; paths are pixel-major, sample-minor.
struct TileJob {
  const Accelerator& tracer;
  const TriangleSoup& soup;
  const PathOptions& opt;
  const CameraRays& camera;
  const AreaLight& light;
};

/// Shades the hits of one bounce: sky on a miss, a shadow ray to the light, and
/// the next path ray. Appends to the shadow and next-ray lists.
void shade_bounce(const TileJob& job, int bounce, const std::vector<std::size_t>& active, const std::vector<Ray>& rays,
                  const std::vector<Hit>& hits, std::vector<PathState>& paths, std::vector<Sampler>& samplers,
                  std::vector<Ray>& shadow, std::vector<std::size_t>& shadow_owner, std::vector<Vec3f>& shadow_value,
                  std::vector<Ray>& next, std::vector<std::size_t>& next_owner) {
  const AreaLight& light = job.light;
  for (std::size_t k = 0; k < active.size(); ++k) {
    const std::size_t i = active[k];
    PathState& path = paths[i];
    const Hit& h = hits[k];
    if (!h.hit()) {
      path.radiance += Vec3f{path.throughput.x * sky(rays[k].dir).x, path.throughput.y * sky(rays[k].dir).y,
                             path.throughput.z * sky(rays[k].dir).z};
      path.alive = false;
      continue;
    }
    const auto tri = job.soup.corners(h.prim);
    Vec3f n = job.soup.unit_normal(h.prim);
    if (dot(n, rays[k].dir) > 0) n = -n;  // face the incoming ray: both sides are diffuse
    const SurfacePoint sp = surface_point(tri, h.u, h.v);
    Sampler& rng = samplers[i];
    // Next-event estimation toward a uniform point of the light.
    const Vec3f lp = light.corner + light.edge_u * rng.next() + light.edge_v * rng.next();
    const Vec3f to_light = lp - sp.p;
    const float dist2 = dot(to_light, to_light);
    const Vec3f wl = to_light / std::sqrt(dist2);
    const float cos_s = dot(n, wl), cos_l = -dot(light.normal, wl);
    if (cos_s > 0 && cos_l > 0 && dist2 > 0) {
      const float g = job.opt.albedo / kPi * light.radiance * cos_s * cos_l * light.area / dist2;
      Ray r = spawn_ray(sp, n, wl);
      r.dir = lp - r.org;  // reach the light sample at t = 1
      r.tfar = 1.0f;
      shadow.push_back(r);
      shadow_owner.push_back(i);
      shadow_value.push_back(path.throughput * g);
    }
    if (bounce >= job.opt.bounces) {
      path.alive = false;
      continue;
    }
    // Cosine-weighted bounce: the Lambertian f cos / pdf is the albedo.
    const float r1 = rng.next(), r2 = rng.next();
    const Vec3f wi = sample_cosine(n, r1, r2);
    path.throughput *= job.opt.albedo;
    next.push_back(spawn_ray(sp, n, wi));
    next_owner.push_back(i);
  }
}

/// Renders one tile into `image`.
void render_tile(const TileJob& job, int x0, int y0, int x1, int y1, Image& image, ThreadStats& ts,
                 std::uint64_t& nan_pixels) {
  const int spp = job.opt.spp;
  const int strata = int(std::ceil(std::sqrt(double(spp))));
  std::vector<PathState> paths;
  std::vector<Sampler> samplers;
  std::vector<Ray> rays;
  std::vector<std::size_t> active;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      for (int s = 0; s < spp; ++s) {
        const std::uint64_t pixel = std::uint64_t(y) * std::uint64_t(job.opt.width) + std::uint64_t(x);
        samplers.emplace_back(job.opt.seed, pixel, std::uint64_t(s));
        Sampler& rng = samplers.back();
        const float sx = (float(s % strata) + rng.next()) / float(strata);
        const float sy = (float((s / strata) % strata) + rng.next()) / float(strata);
        rays.push_back(job.camera.ray(x, y, sx, sy));
        active.push_back(paths.size());
        paths.emplace_back();
      }
  std::vector<Hit> hits;
  std::vector<char> blocked;
  for (int bounce = 0; !active.empty(); ++bounce) {
    trace_timed(job.tracer, rays, hits, bounce == 0 ? job.opt.packet_width : 1, ts, bounce);
    std::vector<Ray> shadow, next;
    std::vector<std::size_t> shadow_owner, next_owner;
    std::vector<Vec3f> shadow_value;
    shade_bounce(job, bounce, active, rays, hits, paths, samplers, shadow, shadow_owner, shadow_value, next,
                 next_owner);
    occluded_timed(job.tracer, shadow, blocked, ts, bounce);
    for (std::size_t k = 0; k < shadow.size(); ++k)
      if (!blocked[k]) paths[shadow_owner[k]].radiance += shadow_value[k];
    rays = std::move(next);
    active = std::move(next_owner);
  }
  std::size_t i = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      Vec3f sum{0, 0, 0};
      for (int s = 0; s < spp; ++s, ++i) sum += paths[i].radiance;
      sum = sum / float(spp);
      if (!is_finite(sum)) ++nan_pixels, sum = {0, 0, 0};
      float* p = image.pixel(x, y);
      p[0] = sum.x, p[1] = sum.y, p[2] = sum.z;
    }
}

}  // namespace

Image render_path(const Accelerator& tracer, const TriangleSoup& soup, const PathOptions& options, PathStats* stats,
                  const RenderProgress& progress) {
  IeeeTasks ieee;  // IEEE arithmetic here and in every task, camera set-up included (geometry/core/fp_env.h)
  const auto start = std::chrono::steady_clock::now();
  Image image(options.width, options.height);
  const CameraRays camera(options.camera, options.width, options.height);
  const AreaLight light(soup.bounds());
  const TileJob job{tracer, soup, options, camera, light};
  const int tiles_x = (options.width + kTile - 1) / kTile, tiles_y = (options.height + kTile - 1) / kTile;
  const std::uint64_t total = std::uint64_t(tiles_x) * std::uint64_t(tiles_y);
  std::atomic<std::uint64_t> done{0}, nan_pixels{0};
  const std::size_t depth = std::size_t(options.bounces) + 1;
  tbb::combinable<ThreadStats> per_thread([&] {
    return ThreadStats{std::vector<std::uint64_t>(depth, 0), std::vector<double>(depth, 0.0),
                       std::vector<RayCounters>(depth), options.count};
  });
  tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, total, 1), [&](const auto& range) {
    for (std::uint64_t t = range.begin(); t < range.end(); ++t) {
      const int x0 = int(t % std::uint64_t(tiles_x)) * kTile, y0 = int(t / std::uint64_t(tiles_x)) * kTile;
      std::uint64_t nans = 0;
      render_tile(job, x0, y0, std::min(x0 + kTile, options.width), std::min(y0 + kTile, options.height), image,
                  per_thread.local(), nans);
      nan_pixels += nans;
      const std::uint64_t d = done.fetch_add(1) + 1;
      if (progress) progress(d, total);
    }
  }, ieee.context());
  if (stats) {
    *stats = {};
    stats->rays_by_bounce.assign(depth, 0);
    stats->trace_seconds_by_bounce.assign(depth, 0.0);
    stats->counters_by_bounce.assign(depth, RayCounters{});
    per_thread.combine_each([&](const ThreadStats& ts) {
      for (std::size_t b = 0; b < depth; ++b) {
        stats->rays_by_bounce[b] += ts.rays[b];
        stats->trace_seconds_by_bounce[b] += ts.seconds[b];
        stats->counters_by_bounce[b] += ts.counters[b];
      }
    });
    for (std::uint64_t r : stats->rays_by_bounce) stats->rays += r;
    stats->nan_pixels = nan_pixels.load();
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return image;
}

}  // namespace bsprt
