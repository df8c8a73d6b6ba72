#include "apps/heat_map.h"

#include <fmt/core.h>
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "bsprt/error.h"
#include "geometry/core/fp_env.h"

namespace bsprt {
namespace {

constexpr int kBarWidth = 110;

/// Inferno colour map (matplotlib), 9 control points, linearly interpolated.
std::array<float, 3> inferno(float x) {
  static constexpr float kMap[9][3] = {{0.001f, 0.000f, 0.014f}, {0.120f, 0.047f, 0.283f}, {0.335f, 0.060f, 0.429f},
                                       {0.533f, 0.134f, 0.416f}, {0.729f, 0.212f, 0.333f}, {0.894f, 0.337f, 0.200f},
                                       {0.984f, 0.536f, 0.044f}, {0.973f, 0.765f, 0.161f}, {0.988f, 0.998f, 0.645f}};
  x = std::clamp(std::isfinite(x) ? x : 0.0f, 0.0f, 1.0f) * 8.0f;
  const int i = std::min(int(x), 7);
  const float f = x - float(i);
  return {kMap[i][0] + f * (kMap[i + 1][0] - kMap[i][0]), kMap[i][1] + f * (kMap[i + 1][1] - kMap[i][1]),
          kMap[i][2] + f * (kMap[i + 1][2] - kMap[i][2])};
}

/// Diverging map: -1 blue, 0 white, +1 red.
std::array<float, 3> diverging(float x) {
  x = std::clamp(std::isfinite(x) ? x : 0.0f, -1.0f, 1.0f);
  return x < 0 ? std::array<float, 3>{1 + x * 0.85f, 1 + x * 0.6f, 1.0f}
               : std::array<float, 3>{1.0f, 1 - x * 0.75f, 1 - x * 0.85f};
}

/// Linear-light value that writes as sRGB `c` (images are stored linear).
float linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

void put(Image& img, int x, int y, const std::array<float, 3>& srgb) {
  if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
  float* p = img.pixel(x, y);
  p[0] = linear(srgb[0]), p[1] = linear(srgb[1]), p[2] = linear(srgb[2]);
}

/// Draws text with stb_easy_font (quads rasterised by hand: axis-aligned).
void draw_text(Image& img, int x, int y, const std::string& text) {
  static thread_local std::vector<char> buffer(1 << 16);
  const int quads = stb_easy_font_print(float(x), float(y), const_cast<char*>(text.c_str()), nullptr,
                                        buffer.data(), int(buffer.size()));
  const float* v = reinterpret_cast<const float*>(buffer.data());
  for (int q = 0; q < quads; ++q, v += 16) {  // 4 vertices of x, y, z, colour
    const int x0 = int(v[0]), y0 = int(v[1]), x1 = int(v[8]), y1 = int(v[9]);
    for (int yy = y0; yy < y1; ++yy)
      for (int xx = x0; xx < x1; ++xx) put(img, xx, yy, {0.95f, 0.95f, 0.95f});
  }
}

/// Copies the map into a wider image and draws the bar at the right.
template <typename Map>
Image with_bar(const std::vector<float>& norm, int width, int height, Map map, float lo, float hi,
               const std::string& title) {
  Image img(width + kBarWidth, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) put(img, x, y, map(norm[std::size_t(y) * width + x]));
  for (int y = 0; y < height; ++y)
    for (int x = width; x < width + kBarWidth; ++x) put(img, x, y, {0.1f, 0.1f, 0.12f});
  const int top = 28, bottom = height - 12, bx = width + 12;
  for (int y = top; y < bottom; ++y) {
    const float f = 1.0f - float(y - top) / float(std::max(1, bottom - top - 1));
    for (int x = bx; x < bx + 18; ++x) put(img, x, y, map(lo < 0 ? 2 * f - 1 : f));
  }
  draw_text(img, width + 6, 6, title);
  draw_text(img, bx + 24, top, fmt::format("{:.4g}", hi));
  draw_text(img, bx + 24, (top + bottom) / 2 - 4, fmt::format("{:.4g}", 0.5f * (lo + hi)));
  draw_text(img, bx + 24, bottom - 8, fmt::format("{:.4g}", lo));
  return img;
}

}  // namespace

std::string heat_metric_name(HeatMetric m) {
  switch (m) {
    case HeatMetric::Time: return "time";
    case HeatMetric::Nodes: return "nodes";
    case HeatMetric::Tests: return "tests";
  }
  return "?";
}

HeatMetric parse_heat_metric(const std::string& name) {
  for (HeatMetric m : {HeatMetric::Time, HeatMetric::Nodes, HeatMetric::Tests})
    if (heat_metric_name(m) == name) return m;
  throw UsageError("unknown heat metric '" + name + "' (expected time, nodes or tests)");
}

std::vector<float> pixel_costs(const Accelerator& tracer, const RenderOptions& options, HeatMetric metric, int repeats) {
  IeeeTasks ieee;  // IEEE arithmetic here and in every task, camera set-up included (geometry/core/fp_env.h)
  const CameraRays camera(options.camera, options.width, options.height);
  std::vector<float> cost(std::size_t(options.width) * std::size_t(options.height), 0.0f);
  tbb::parallel_for(0, options.height, [&](int y) {
    for (int x = 0; x < options.width; ++x) {
      const Ray ray = camera.ray(x, y);
      float& c = cost[std::size_t(y) * options.width + x];
      if (metric == HeatMetric::Time) {
        std::array<float, 9> t{};
        const int n = std::clamp(repeats, 1, 9);
        for (int r = 0; r < n; ++r) {
          const auto t0 = std::chrono::steady_clock::now();
          const Hit h = tracer.trace(ray);
          const auto t1 = std::chrono::steady_clock::now();
          asm volatile("" : : "r"(h.t) : "memory");
          t[r] = float(std::chrono::duration<double, std::nano>(t1 - t0).count());
        }
        std::nth_element(t.begin(), t.begin() + n / 2, t.begin() + n);
        c = t[n / 2];
      } else {
        RayCounters rc;
        tracer.trace(ray, &rc);
        // Nodes: every kind of node a tracer counts, box nodes too (bvh8's map was blank).
        c = metric == HeatMetric::Nodes ? float(rc.kd_node_visits + rc.bsp_node_visits + rc.box_node_visits)
                                        : float(rc.triangle_tests);
      }
    }
  }, ieee.context());
  return cost;
}

Image heat_image(const std::vector<float>& cost, int width, int height, float scale_max, const std::string& title) {
  float hi = scale_max > 0 ? scale_max : *std::max_element(cost.begin(), cost.end());
  if (!(hi > 0)) hi = 1;
  std::vector<float> norm(cost.size());
  std::transform(cost.begin(), cost.end(), norm.begin(), [&](float c) { return c / hi; });
  return with_bar(norm, width, height, inferno, 0.0f, hi, title);
}

Image heat_difference_image(const std::vector<float>& a, const std::vector<float>& b, int width, int height,
                            const std::string& title) {
  std::vector<float> diff(a.size());
  float hi = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff[i] = a[i] - b[i], hi = std::max(hi, std::abs(diff[i]));
  if (!(hi > 0)) hi = 1;
  for (float& d : diff) d /= hi;
  return with_bar(diff, width, height, diverging, -hi, hi, title);
}

}  // namespace bsprt
