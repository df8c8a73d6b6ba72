/// \file test_fp_env.cpp
/// The floating-point environment bsprt computes in (geometry/core/fp_env.h):
/// a caller with flush-to-zero and denormals-are-zero, or a oneTBB arena that
/// hands them to its tasks, must not change a tree, a certificate or a hit.
///
/// Found 2026-12-07: after an Embree tracer had been made in a process,
/// `verify` refused a valid BSP tree of a scene with subnormal coordinates.
/// Embree 3.13's rtcCommitScene sets FTZ and DAZ while it runs TBB tasks;
/// when that is a thread's first use of TBB, the thread's implicit arena
/// captures them in its default context, and every later parallel loop
/// without a context of its own ran with them (the verifier's plane table
/// then held intervals with subnormals read as zero).
#include <catch2/catch.hpp>

#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <thread>
#include <tuple>
#include <vector>

#include "apps/heat_map.h"
#include "apps/path_tracer.h"
#include "apps/render.h"
#include "builder/accel_factory.h"
#include "builder/bsp/bsp_build.h"
#include "builder/bsp/bsp_flat_io.h"
#include "builder/bsp/bsp_flatten.h"
#include "builder/kd/kd_build.h"
#include "builder/kd/kd_file.h"
#include "builder/tree_file.h"
#include "geometry/core/fp_env.h"
#include "robust/degenerate.h"
#include "traverse/trace_parallel.h"
#include "verify/verify.h"
#include "verify/verify_file.h"

using namespace bsprt;

#if BSPRT_HAS_MXCSR
namespace {

constexpr unsigned kFtzDaz = IeeeScope::kFtz | IeeeScope::kDaz;

/// Sets MXCSR to `value` on this thread for its lifetime, then restores it
/// (also when a check throws, so that later cases in the same process start clean).
class Mxcsr {
 public:
  explicit Mxcsr(unsigned value) : saved_(_mm_getcsr()) { _mm_setcsr(value); }
  ~Mxcsr() { _mm_setcsr(saved_); }
  Mxcsr(const Mxcsr&) = delete;
  Mxcsr& operator=(const Mxcsr&) = delete;

 private:
  unsigned saved_;
};

/// Runs f on a new thread, which has no TBB state of its own yet, and rethrows
/// what it threw.
template <typename F>
void on_new_thread(F&& f) {
  std::exception_ptr error;
  std::thread t([&] {
    try {
      f();
    } catch (...) {
      error = std::current_exception();
    }
  });
  t.join();
  if (error) std::rethrow_exception(error);
}

/// What Embree 3.13.5's rtcCommitScene does to a thread whose first use of TBB
/// it is, without bsprt in between: one triangle, committed.
void commit_raw_embree_scene() {
  RTCDevice device = rtcNewDevice(nullptr);
  REQUIRE(device != nullptr);
  RTCScene scene = rtcNewScene(device);
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3));
  const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::copy(corners, corners + 9, v);
  auto* i = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), 1));
  i[0] = 0, i[1] = 1, i[2] = 2;
  rtcCommitGeometry(g);
  rtcAttachGeometry(scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scene);
  rtcReleaseScene(scene);
  rtcReleaseDevice(device);
}

/// Four triangles with coordinates near 2^-138 (subnormal floats): the scene
/// of the regression test "bsp build: a scene with subnormal coordinates...".
TriangleSoup subnormal_scene() {
  const float grid[12][3] = {{0, 5, 1}, {1, 5, 0}, {1, 6, 2}, {3, 4, 2},   {3, 5, 2}, {4, 5, 2},
                             {1, 2, 3}, {1, 2, 5}, {2, 2, 5}, {2, 1, 4.5f}, {4, 1, 6.5f}, {2, 1, 4}};
  TriangleSoup s;
  for (const auto& g : grid) s.vertices.push_back({std::ldexp(g[0], -140), std::ldexp(g[1], -140), std::ldexp(g[2], -140)});
  s.triangles = {{5, 4, 3}, {6, 8, 7}, {2, 1, 0}, {9, 10, 11}};
  classify_degenerate(s);
  return s;
}

/// Rays from points around the scene to every corner and triangle centre.
std::vector<Ray> rays_of(const TriangleSoup& s) {
  const float from[4][3] = {{-1, -1, -1}, {7, 8, 9}, {2.5f, 3, -4}, {-3, 9, 2}};
  std::vector<Ray> rays;
  for (const auto& f : from)
    for (std::uint32_t t = 0; t < s.size(); ++t)
      for (int k = 0; k <= 3; ++k) {
        const Vec3f o{std::ldexp(f[0], -140), std::ldexp(f[1], -140), std::ldexp(f[2], -140)};
        const Vec3f target = k < 3 ? s.corner(t, k) : (s.corner(t, 0) + s.corner(t, 1) + s.corner(t, 2)) * (1.0f / 3.0f);
        Ray r;
        r.org = o;
        r.dir = target - o;
        rays.push_back(r);
      }
  return rays;
}

/// What a build, a verify and the tracers make of the scene.
struct Outcome {
  std::vector<std::byte> bsp_file, kd_file;
  bool certified = false;
  std::string failure;
  std::vector<Hit> exact, bsp, kd;
};

Outcome run_all(const TriangleSoup& s, const std::vector<Ray>& rays) {
  Outcome o;
  BspConfig config;
  config.parallel_min_triangles = 1;  // both subtrees as tasks, so that tasks build
  const BspTree tree = build_bsp(s, config);
  const FlatBspTree flat = flatten_bsp(s, tree);
  o.bsp_file = bsp_tree_file(s, tree, flat).bytes();
  o.kd_file = kd_tree_file(build_kd(s), s).bytes();
  const TreeFileReader reader("(memory)", o.bsp_file);
  const VerifyReport r = verify_bsp(s, read_verify_input(reader, s));
  o.certified = r.certified;
  o.failure = r.failure ? r.failure->describe() : "";
  // Tracers are traced as the CLI and the public API trace them: in trace_parallel's
  // tasks (Accelerator::trace itself leaves the environment to its caller).
  for (const char* name : {"exact", "bsp", "kd"}) {
    const auto tracer = make_tracer(name, s, AccelOptions{});
    std::vector<Hit>& hits = std::string(name) == "exact" ? o.exact : std::string(name) == "bsp" ? o.bsp : o.kd;
    hits.resize(rays.size());
    trace_parallel(*tracer, rays, hits, ParallelTrace{1, false, 1, {}});  // a task per ray
  }
  return o;
}

void check_same(const Outcome& want, const Outcome& got) {
  CHECK(got.bsp_file == want.bsp_file);
  CHECK(got.kd_file == want.kd_file);
  INFO(got.failure);
  CHECK(got.certified);
  REQUIRE(got.exact.size() == want.exact.size());
  for (std::size_t i = 0; i < want.exact.size(); ++i) {
    CAPTURE(i);
    CHECK(got.exact[i].prim == want.exact[i].prim);
    CHECK(got.exact[i].t == want.exact[i].t);
    CHECK(got.bsp[i].prim == want.exact[i].prim);  // certified modes equal the exact reference
    CHECK(got.bsp[i].t == want.exact[i].t);
    CHECK(got.kd[i].prim == want.exact[i].prim);
    CHECK(got.kd[i].t == want.exact[i].t);
  }
}

/// How many of `n` tasks of a plain parallel_for (no context of its own) ran
/// in IEEE arithmetic.
int ieee_tasks_of_plain_loop(int n) {
  std::atomic<int> ieee{0};
  tbb::parallel_for(0, n, [&](int) { ieee += IeeeScope::active() ? 1 : 0; });
  return ieee.load();
}

}  // namespace

TEST_CASE("fp env: IeeeScope sets IEEE arithmetic, then gives the caller its settings back with the flags raised inside", "[fp_env]") {
  const unsigned caller = IeeeScope::kDefault | kFtzDaz | (1u << 13);  // FTZ, DAZ, round down
  unsigned after = 0;
  {
    const Mxcsr set(caller);
    {
      const IeeeScope scope;
      CHECK(IeeeScope::active());
      volatile float tiny = 0x1p-140f;  // subnormal: DAZ reads it as 0, FTZ flushes the product
      volatile float product = tiny * 2.0f;
      CHECK(product == 0x1p-139f);
      volatile float third = 1.0f;
      third = third / 3.0f;  // round to nearest, and raises the inexact flag
      CHECK(third == 1.0f / 3.0f);
    }
    after = _mm_getcsr();
  }
  CHECK((after & IeeeScope::kControl) == caller);
  CHECK((after & 0x20u) != 0);  // precision (inexact) flag raised inside the scope is kept
}

TEST_CASE("fp env: a caller with FTZ and DAZ, in an arena that hands them to its tasks, gets the same trees, certificate and hits", "[fp_env][regression]") {
  const TriangleSoup s = subnormal_scene();
  const std::vector<Ray> rays = rays_of(s);
  Outcome want;
  {
    const Mxcsr clean(IeeeScope::kDefault);
    want = run_all(s, rays);
  }
  INFO(want.failure);
  REQUIRE(want.certified);
  int hits = 0;
  for (const Hit& h : want.exact) hits += h.hit();
  CHECK(hits > 40);  // most of the 64 rays hit something

  // A thread with FTZ and DAZ (as Embree advises), and an arena made then: its
  // default context hands them to every task run without a context of its own.
  Outcome got;
  int plain_ieee = -1, block_ieee = 0;
  unsigned after = 0;
  {
    const Mxcsr poison(IeeeScope::kDefault | kFtzDaz);
    tbb::task_arena poisoned;
    poisoned.initialize();
    poisoned.execute([&] {
      plain_ieee = ieee_tasks_of_plain_loop(64);
      std::atomic<int> n{0};
      for_each_block(64, 1, [&](std::size_t, std::size_t) { n += IeeeScope::active() ? 1 : 0; });
      block_ieee = n.load();
      got = run_all(s, rays);
    });
    after = _mm_getcsr();
  }
  REQUIRE(plain_ieee == 0);  // the setting this test is about: tasks do inherit FTZ and DAZ
  CHECK(block_ieee == 64);   // bsprt's loops do not
  CHECK((after & kFtzDaz) == kFtzDaz);  // and the caller keeps its own settings
  check_same(want, got);
}

TEST_CASE("fp env: renders, heat maps and path tracing in an arena with FTZ and DAZ equal the clean ones", "[fp_env][regression]") {
  // The scene at 2^-132: the camera's pixel steps are subnormal too.
  TriangleSoup s = subnormal_scene();
  for (Vec3f& v : s.vertices) v = v * 0x1p8f;
  classify_degenerate(s);
  const auto tracer = [&] {
    const Mxcsr clean(IeeeScope::kDefault);
    return make_tracer("bsp", s, AccelOptions{});
  }();
  RenderOptions cast;
  cast.width = 64, cast.height = 48;
  cast.camera = Camera{Vec3f{8, 10, -6} * 0x1p-132f, Vec3f{2, 3.5f, 3.5f} * 0x1p-132f, Vec3f{0, 1, 0}, 30.0f};
  PathOptions path;
  path.width = 32, path.height = 24, path.spp = 1, path.bounces = 1, path.camera = cast.camera;
  const auto run = [&] {
    RenderStats stats;
    Image a = render_cast(*tracer, s, cast, &stats);
    std::vector<float> tests = pixel_costs(*tracer, cast, HeatMetric::Tests, 1);
    PathStats path_stats;
    Image b = render_path(*tracer, s, path, &path_stats);
    CHECK(path_stats.nan_pixels == 0);
    return std::make_tuple(std::move(a.rgb), std::move(tests), std::move(b.rgb), stats.hits);
  };
  std::tuple<std::vector<float>, std::vector<float>, std::vector<float>, std::uint64_t> want, got;
  {
    const Mxcsr clean(IeeeScope::kDefault);
    want = run();
  }
  CHECK(std::get<3>(want) > 40);  // of 3,072 pixels, the four small triangles cover 86
  // Found by this test: the eye-light shading took the normal of a triangle near 2^-130 from a
  // float cross product, which underflowed to zero, and 86 pixels were NaN.
  CHECK(std::count_if(std::get<0>(want).begin(), std::get<0>(want).end(), [](float v) { return std::isnan(v); }) == 0);
  {
    const Mxcsr poison(IeeeScope::kDefault | kFtzDaz);
    tbb::task_arena poisoned;
    poisoned.initialize();
    poisoned.execute([&] { got = run(); });
  }
  CHECK(std::get<3>(got) == std::get<3>(want));
  CHECK(std::get<0>(got) == std::get<0>(want));
  CHECK(std::get<1>(got) == std::get<1>(want));
  CHECK(std::get<2>(got) == std::get<2>(want));
}

TEST_CASE("fp env: after Embree made a thread's tasks use FTZ and DAZ, bsprt's loops compute in IEEE arithmetic and verify certifies a subnormal tree", "[fp_env][regression]") {
  const TriangleSoup s = subnormal_scene();
  const std::vector<Ray> rays = rays_of(s);
  Outcome want;
  {
    const Mxcsr clean(IeeeScope::kDefault);
    tbb::task_arena arena;  // made in IEEE arithmetic, whatever this process did before
    want = arena.execute([&] { return run_all(s, rays); });
  }
  REQUIRE(want.certified);
  // On a new thread, Embree's scene commit is the thread's first use of TBB, as in a
  // program that uses Embree before bsprt. Embree 3.13.5 then leaves FTZ and DAZ in
  // the default context of the thread's implicit arena.
  Outcome got;
  int plain_ieee = -1, block_ieee = 0;
  on_new_thread([&] {
    commit_raw_embree_scene();
    plain_ieee = ieee_tasks_of_plain_loop(64);
    std::atomic<int> n{0};
    for_each_block(64, 1, [&](std::size_t, std::size_t) { n += IeeeScope::active() ? 1 : 0; });
    block_ieee = n.load();
    got = run_all(s, rays);
  });
  REQUIRE(plain_ieee < 64);  // the setting this test is about (Embree 3.13.5's commit)
  CHECK(block_ieee == 64);
  check_same(want, got);  // verify refused the tree before the fix
}

TEST_CASE("fp env: making an Embree tracer leaves the caller's own TBB loops in IEEE arithmetic", "[fp_env][regression]") {
  const TriangleSoup s = subnormal_scene();
  int plain_ieee = -1;
  on_new_thread([&] {
    make_tracer("embree", s, AccelOptions{});  // this thread's first use of TBB
    plain_ieee = ieee_tasks_of_plain_loop(64);
  });
  CHECK(plain_ieee == 64);  // make_tracer made the implicit arena under an IeeeScope
}
#endif
