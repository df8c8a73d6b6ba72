// bench_embree_plain MESH [RAYS] [--passes P] [--count N] [--quality medium|high]: the timing harness
// against a plain rtcIntersect1 loop (issue #26 item 0). The same Embree scene
// settings as EmbreeTracer (robust, high-quality build, degenerate triangles
// left out), the same rays (a .rays file, or N random rays), one thread, best
// of P passes each:
//   plain     for each ray: RTCRayHit, rtcIntersect1, store t/prim/u/v
//             (--quality medium builds this loop's scene without spatial splits,
//             to see what Embree's high-quality build is worth on these rays)
//   batch     EmbreeTracer::trace_batch over all rays (what trace_parallel calls)
//   harness   trace_parallel on a 1-thread arena: what `bsprt trace --accel
//             embree --threads 1` and `bsprt bench` time
// Prints ns/ray of each and its ratio to the plain loop, and checks the hits agree.
// --only NAME runs one loop and prints nothing (for per-ray instruction counts:
// cachegrind with N rays minus cachegrind with 1 ray, scripts/ray_profile.sh's way).
#include <embree3/rtcore.h>
#include <fmt/core.h>
#include <oneapi/tbb/task_arena.h>

#include <chrono>
#include <cstring>
#include <string>
#include <vector>

#include "bsprt/io.h"
#include "geometry/io/load_mesh.h"
#include "geometry/scenes/ray_gen.h"
#include "traverse/embree/embree_tracer.h"
#include "traverse/trace_parallel.h"

namespace {

using Clock = std::chrono::steady_clock;

template <typename F>
double best_of(int passes, F&& f) {
  double best = 1e30;
  for (int p = 0; p < passes; ++p) {
    const auto t0 = Clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
  }
  return best;
}

/// The plain Embree scene: what every Embree tutorial does, with EmbreeTracer's flags.
struct PlainScene {
  RTCDevice device = rtcNewDevice(nullptr);
  RTCScene scene = nullptr;
  std::vector<std::uint32_t> prim_of;
  PlainScene(const bsprt::TriangleSoup& soup, RTCBuildQuality quality) {
    scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, quality);
    for (std::uint32_t i = 0; i < soup.size(); ++i)
      if (!soup.is_degenerate(i)) prim_of.push_back(i);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), soup.vertices.size()));
    std::memcpy(vb, soup.vertices.data(), soup.vertices.size() * 3 * sizeof(float));
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(unsigned), prim_of.size()));
    for (std::size_t j = 0; j < prim_of.size(); ++j)
      for (int k = 0; k < 3; ++k) ib[3 * j + k] = soup.triangles[prim_of[j]][k];
    rtcSetGeometryBuildQuality(g, quality);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
  }
  ~PlainScene() {
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> pos;
  int passes = 5;
  std::size_t count = 2000000;
  std::string only;  // --only plain|batch|harness: run one loop (for cachegrind counts)
  RTCBuildQuality quality = RTC_BUILD_QUALITY_HIGH;  // --quality medium: the plain loop's scene without spatial splits
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--passes" && i + 1 < argc) passes = std::stoi(argv[++i]);
    else if (a == "--count" && i + 1 < argc) count = std::stoul(argv[++i]);
    else if (a == "--only" && i + 1 < argc) only = argv[++i];
    else if (a == "--quality" && i + 1 < argc) {
      const std::string q = argv[++i];
      if (q != "medium" && q != "high") {
        fmt::print(stderr, "--quality takes medium or high, got '{}'\n", q);
        return 2;
      }
      quality = q == "medium" ? RTC_BUILD_QUALITY_MEDIUM : RTC_BUILD_QUALITY_HIGH;
    }
    else pos.push_back(a);
  }
  if (pos.empty()) {
    fmt::print(stderr, "usage: bench_embree_plain MESH [RAYS] [--passes P] [--count N] [--quality medium|high]\n");
    return 2;
  }
  const bsprt::TriangleSoup soup = bsprt::load_mesh(pos[0]);
  const std::vector<bsprt::Ray> rays = pos.size() > 1 ? bsprt::read_rays(pos[1]) : bsprt::random_rays(soup, count, 1);
  for (std::size_t i = 0; i < rays.size(); ++i)
    if (bsprt::embree_cannot_trace(rays[i])) {
      fmt::print(stderr, "ray {} is outside Embree's domain\n", i);
      return 2;
    }
  const PlainScene plain(soup, quality);
  const bsprt::EmbreeTracer tracer(soup);
  std::vector<bsprt::Hit> h_plain(rays.size()), h_batch(rays.size()), h_harness(rays.size());
  tbb::task_arena one(1);
  const auto run = [&](const char* name) { return only.empty() || only == name ? passes : 0; };
  const double t_plain = best_of(run("plain"), [&] {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const bsprt::Ray& r = rays[i];
      RTCRayHit rh;
      rh.ray.org_x = r.org.x, rh.ray.org_y = r.org.y, rh.ray.org_z = r.org.z, rh.ray.tnear = r.tnear;
      rh.ray.dir_x = r.dir.x, rh.ray.dir_y = r.dir.y, rh.ray.dir_z = r.dir.z, rh.ray.tfar = r.tfar;
      rh.ray.time = 0.0f, rh.ray.mask = ~0u, rh.ray.flags = 0;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID, rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(plain.scene, &ctx, &rh);
      h_plain[i] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID
                       ? bsprt::Hit{}
                       : bsprt::Hit{rh.ray.tfar, plain.prim_of[rh.hit.primID], rh.hit.u, rh.hit.v};
    }
  });
  const double t_batch = best_of(run("batch"), [&] { tracer.trace_batch(rays, h_batch, 1); });
  const double t_harness = best_of(run("harness"), [&] {
    one.execute([&] {
      bsprt::ParallelTrace o;
      o.block = 1024;
      bsprt::trace_parallel(tracer, rays, h_harness, o);
    });
  });
  if (!only.empty()) return 0;
  const bool same = std::memcmp(h_plain.data(), h_batch.data(), rays.size() * sizeof(bsprt::Hit)) == 0 &&
                    std::memcmp(h_plain.data(), h_harness.data(), rays.size() * sizeof(bsprt::Hit)) == 0;
  const double n = double(rays.size());
  const bool high = quality == RTC_BUILD_QUALITY_HIGH;
  fmt::print("{} rays on {} ({} triangles), 1 thread, best of {} passes; plain loop's build quality {}; hits identical: {}\n",
             rays.size(), pos[0], soup.size(), passes, high ? "high" : "medium",
             same ? "yes" : high ? "NO" : "no (another tree: ties may differ)");
  fmt::print("| loop | ns/ray | Mrays/s | vs plain |\n|---|---:|---:|---:|\n");
  for (const auto& [name, t] : {std::pair{"plain rtcIntersect1 loop", t_plain}, std::pair{"EmbreeTracer::trace_batch", t_batch},
                                std::pair{"trace_parallel (bsprt trace, bench)", t_harness}})
    fmt::print("| {} | {:.1f} | {:.2f} | {:.2f}x |\n", name, 1e9 * t / n, n / t * 1e-6, t / t_plain);
  return same || !high ? 0 : 1;
}
