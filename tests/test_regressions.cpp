// Named regression tests: every fuzzer finding (fuzz/) and every stiff-case
// failure becomes one test here, with the input written out in code.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <utility>
#include <vector>

#include "geometry/scenes/default_scene.h"
#include "bsprt/error.h"
#include "geometry/io/load_mesh.h"
#include "builder/accel_factory.h"
#include "builder/bsp/bsp_build.h"
#include "builder/bsp/bsp_flat_io.h"
#include "builder/bsp/bsp_flatten.h"
#include "builder/kd/kd_build.h"
#include "builder/kd/kd_file.h"
#include "builder/tree_file.h"
#include "verify/verify.h"
#include "verify/verify_file.h"
#include "robust/certified_intersector.h"
#include "robust/degenerate.h"
#include "robust/exact_tracer.h"
#include "traverse/brute_force.h"
#include "traverse/simd/cpu_features.h"
#include "stiff_util.h"
#include "test_util.h"

using namespace bsprt;
using namespace bsprt::test;

/// Adds triangle (a, b, c) with its own vertices.
static void add_tri(TriangleSoup& s, Vec3f a, Vec3f b, Vec3f c) {
  const auto n = std::uint32_t(s.vertices.size());
  s.vertices.insert(s.vertices.end(), {a, b, c});
  s.triangles.push_back({n, n + 1, n + 2});
  s.degenerate.push_back(0);
}

static Ray ray_of(Vec3f org, Vec3f dir) {
  Ray r;
  r.org = org, r.dir = dir;
  return r;
}

// Found by tests/test_stiff.cpp (stacks, axis-plane rays): the exact reference
// counted a ray lying in a triangle's plane and touching only its corner
// (CGAL's intersection is then a single point) as a hit, while every bsprt
// tracer (and its own documentation) treats rays in the plane as misses.
TEST_CASE("exact reference: a ray in a triangle's plane touching a corner misses", "[regression]") {
  TriangleSoup s;
  add_tri(s, {0.5f, 0.25f, 1}, {2.5f, 0.25f, 1}, {0.5f, 2.25f, 1});
  const Ray corner = ray_of({1.21042895f, 3.63322997f, 1}, {-0.710428953f, -1.38322997f, 0});
  const Ray edge = ray_of({-1, 0.25f, 1}, {1, 0, 0});  // along the edge y = 0.25
  for (const char* accel : {"exact", "brute-certified", "brute"}) {
    INFO(accel);
    const auto t = make_tracer(accel, s);
    CHECK_FALSE(t->trace(corner).hit());
    CHECK_FALSE(t->trace(edge).hit());
  }
  // The same corner reached by a slanted ray is a hit.
  const Ray slanted = ray_of({1.21042895f, 3.63322997f, 2}, {-0.710428953f, -1.38322997f, -1});
  CHECK(make_tracer("exact", s)->trace(slanted).hit());
}

// Found by fuzz/fuzz_tree_file (fuzz/corpus/tree_file/crash-bsp-plane-not-cutting-cell,
// stored here with the header patched as the harness patches it): a BSP tree
// file that reads but whose node 109 has a plane that does not cut its cell
// made flatten_bsp throw std::logic_error, which escaped make_tracer (the CLI
// reported an internal error). A bad tree file must be an InputError.
TEST_CASE("tree file: a BSP plane that does not cut its cell is an InputError", "[regression]") {
  const std::string dir = std::string(__FILE__).substr(0, std::string(__FILE__).rfind('/'));
  const TriangleSoup scene = make_icosphere({0.25f, 0.5f, -0.125f}, 1.0f, 1);  // fuzz_tree_file's scene
  AccelOptions o;
  o.tree_path = dir + "/regressions/bsp_plane_not_cutting_cell.tree";
  CHECK_THROWS_AS(make_tracer("bsp", scene, o), InputError);
  CHECK_THROWS_AS(make_tracer("bsp-float", scene, o), InputError);
}

// Found by fuzz_differential once its rays got special directions (a direction
// scaled by 2^-100): Epick's Ray_3(o, d) stores o + d rounded to double, which
// is o itself when d is tiny against o; CGAL then threw "precondition
// violation: ray is degenerate" out of the exact reference (Release builds,
// without CGAL's preconditions, reported a miss).
TEST_CASE("exact reference: a direction tiny against the origin is traced", "[regression]") {
  TriangleSoup s;
  add_tri(s, {-1, -1, 1}, {3, -1, 1}, {-1, 3, 1});
  const ExactTracer exact(s);
  const CertifiedBruteTracer certified(s);
  const Ray r = ray_of({0.25f, 0.25f, -1.0f}, {0, 0, 0x1p-100f});  // -1 + 2^-100 rounds to -1 in double
  for (const Accelerator* t : {static_cast<const Accelerator*>(&exact), static_cast<const Accelerator*>(&certified)}) {
    Hit h;
    REQUIRE_NOTHROW(h = t->trace(r));
    CHECK(h.prim == 0);
    CHECK(h.t == 0x1p101f);  // 2 / 2^-100
  }
  Ray line = r;  // a segment starting behind the origin takes the Line_3 query
  line.tnear = -1e30f;
  CHECK(exact.trace(line).t == 0x1p101f);
}

// The same rounding without degeneracy, found while fixing the finding above:
// o + d rounded to double rotated the candidate query ray, which then passed
// below the edge that the exact ray hits, and the only triangle was lost.
TEST_CASE("exact reference: candidates come from the exact ray when o + d rounds in double", "[regression]") {
  TriangleSoup s;
  const float x = 0x1p40f, y = 1.0f + 0x1p-23f;
  add_tri(s, {x, y, -1}, {x, y, 1}, {x, 3, 0});  // lower edge at y = 1 + 2^-23
  const ExactTracer exact(s);
  const CertifiedBruteTracer certified(s);
  // At t = 2^40 the ray is at (2^40, 1 + 2^-23, 0), the edge's midpoint; in
  // double, 1 + 2^-63 rounds to 1.
  const Ray r = ray_of({0, 1, 0}, {1, 0x1p-63f, 0});
  for (const Accelerator* t : {static_cast<const Accelerator*>(&exact), static_cast<const Accelerator*>(&certified)}) {
    const Hit h = t->trace(r);
    CHECK(h.prim == 0);
    CHECK(h.t == 0x1p40f);
  }
}

// Found by fuzz_load_mesh in CI (2026-11-22): a PLY whose last line is
// "end_header 4 0 0er " with no newline after it. LineCursor put the body one
// byte past the end of the buffer, and the ascii body reader's substr threw
// std::out_of_range (not an InputError). Now the cursor stops at the end, and
// extra tokens on the end_header line are an error with its line number.
TEST_CASE("mesh loader: a PLY ending on its end_header line is an InputError", "[regression]") {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\n";
  const auto load_error = [](const std::string& name, const std::string& bytes) -> std::pair<std::string, std::int64_t> {
    const std::string path = temp_path(name);
    std::ofstream(path, std::ios::binary) << bytes;
    try {
      load_mesh(path);
    } catch (const InputError& e) {
      CHECK(e.file() == path);
      return {e.what(), e.line()};
    }
    return {"", -1};
  };
  // The fuzzer's input, byte for byte (after its format byte).
  const auto fuzzed = load_error("end_header_tokens.ply", head + "end_header 4 0 0er ");
  CHECK(fuzzed.first.find("end_header") != std::string::npos);
  CHECK(fuzzed.second == 9);
  // The same without the stray tokens: the body is empty, so the file ends inside vertex 0.
  const auto bare = load_error("end_header_eof.ply", head + "end_header");
  CHECK(bare.first.find("file ends inside vertex 0") != std::string::npos);
  // Binary: no body at all is a truncation, not a read past the end.
  std::string bin = head + "end_header";
  bin.replace(bin.find("ascii"), 5, "binary_little_endian");
  CHECK(load_error("end_header_eof_bin.ply", bin).first.find("truncated") != std::string::npos);
}

// Found by fuzz_differential (2026-12-01, a long local run): a ray with a
// subnormal direction meets a triangle at an exact t beyond the float range.
// The exact reference rounded it through float(to_double(t)) = inf and built
// an exact number from that infinity: CGAL's assertion is_finite(d) fired
// (sanitizer build); Release builds reported FLT_MAX, while the certified leaf
// test reported infinity. Both now round with robust/nearest_float.h, as IEEE
// does: from FLT_MAX + half an ulp on, infinity; below, a finite float.
// Issue #23 then fixed one convention for every mode: a hit whose exact t
// rounds to +inf is a miss (formats.md: a miss is t = +inf), as the float
// modes always reported (docs/exact-leaf-test.md).
TEST_CASE("exact reference: a hit beyond the float range is a miss in every mode", "[regression]") {
  TriangleSoup s;
  add_tri(s, {-1, -1, 1}, {3, -1, 1}, {-1, 3, 1});
  add_tri(s, {-1, -1, 0x1p100f}, {3, -1, 0x1p100f}, {-1, 3, 0x1p100f});
  const ExactTracer exact(s);
  const CertifiedBruteTracer certified(s);
  const BruteForceTracer brute(s);
  const float inf = std::numeric_limits<float>::infinity();
  for (const Accelerator* t : {static_cast<const Accelerator*>(&exact), static_cast<const Accelerator*>(&certified),
                               static_cast<const Accelerator*>(&brute)}) {
    CAPTURE(t->name());
    // t = 1 / 1e-40, about 1e40: beyond every float, so a miss; the triangle
    // at 2^100 is farther still.
    Hit h;
    REQUIRE_NOTHROW(h = t->trace(ray_of({0.25f, 0.25f, 0}, {0, 0, 1e-40f})));
    CHECK(!h.hit());
    CHECK(h.t == inf);
    // Behind the origin, the same magnitude: -infinity is below tnear = 0, so no hit.
    CHECK(!t->trace(ray_of({0.25f, 0.25f, 0}, {0, 0, -1e-40f})).hit());
    if (t == &brute) continue;  // the float test's own t overflows below: exact modes only
    // t = (2^100 - 2)·2^27, just below 2^127: large but finite, its nearest float is 2^127.
    REQUIRE_NOTHROW(h = t->trace(ray_of({0.25f, 0.25f, 2}, {0, 0, 0x1p-27f})));
    CHECK(h.prim == 1);
    CHECK(h.t == 0x1p127f);
  }
}

// Found reviewing issue #23's change: with tnear = -inf, the exact reference
// took the nearest exact t first and then dropped it for rounding to -inf,
// reporting a miss, while the certified test skips such a triangle and keeps
// a farther, finite hit. A hit beyond the float range is no hit; the next one counts.
TEST_CASE("exact reference: a hit rounding to -inf is skipped, a farther finite hit is the nearest",
          "[regression]") {
  TriangleSoup s;
  add_tri(s, {-1, -1, 1}, {3, -1, 1}, {-1, 3, 1});                                   // t = -1e40
  add_tri(s, {-1, -1, 2 + 0x1p-10f}, {3, -1, 2 + 0x1p-10f}, {-1, 3, 2 + 0x1p-10f});  // t = 2^-10 / 1e-40
  const ExactTracer exact(s);
  const CertifiedBruteTracer certified(s);
  Ray r = ray_of({0.25f, 0.25f, 2}, {0, 0, 1e-40f});
  r.tnear = -std::numeric_limits<float>::infinity();
  for (const Accelerator* t : {static_cast<const Accelerator*>(&exact), static_cast<const Accelerator*>(&certified)}) {
    CAPTURE(t->name());
    const Hit h = t->trace(r);
    CHECK(h.prim == 1);
    CHECK(std::isfinite(h.t));
    CHECK(h.t > 1e36f);
  }
}

// Found by a review of the Python module (2026-12-07): the exact reference
// dropped an infinite bound whatever its side, so a ray with tnear = tfar =
// +inf (or -inf) hit the triangle in front of it, while every certified mode
// missed, and `compare` then counted the correct modes as "lost". No finite t
// lies in [+inf, +inf] or [-inf, -inf], and a hit beyond the float range is
// no hit, so both segments hold none, in every accelerator.
TEST_CASE("exact reference: a segment at +inf or at -inf holds no hit, in every accelerator", "[regression]") {
  TriangleSoup s;
  add_tri(s, {-1, -1, 1}, {3, -1, 1}, {-1, 3, 1});
  const float inf = std::numeric_limits<float>::infinity();
  for (const std::string& name : accel_names()) {
    CAPTURE(name);
    const std::unique_ptr<Accelerator> t = make_tracer(name, s, AccelOptions{});
    Ray r = ray_of({0.25f, 0.25f, 0}, {0, 0, 1});
    REQUIRE(t->trace(r).prim == 0);  // the triangle is in front, at t = 1
    r.tnear = r.tfar = inf;
    CHECK(!t->trace(r).hit());
    // Embree refuses tnear < 0 (a UsageError, docs/api.md); every other mode traces it.
    if (name.rfind("embree", 0) == 0) continue;
    r.tnear = r.tfar = -inf;
    CHECK(!t->trace(r).hit());
    r.dir = {0, 0, -1};  // the plane behind the origin, at t = -1: in [-inf, +inf]
    r.tfar = inf;
    CHECK(t->trace(r).prim == 0);
  }
}

namespace {
/// The bytes of tree file `path` with the 4-byte field at `offset` of section
/// `tag` set to `value`, and the CRC recomputed: a file that passes every
/// container check, as an edit (or a bug) could leave it.
void patch_tree_file(const std::string& path, std::uint32_t tag, std::size_t offset, std::uint32_t value) {
  std::ifstream in(path, std::ios::binary);
  std::vector<char> c((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> bytes(c.size());
  std::memcpy(bytes.data(), c.data(), c.size());
  std::size_t at = 40;  // sections: tag, reserved, size (16 bytes), data padded to 8
  bool found = false;
  while (at + 16 <= bytes.size()) {
    std::uint32_t t;
    std::uint64_t size;
    std::memcpy(&t, &bytes[at], 4);
    std::memcpy(&size, &bytes[at + 8], 8);
    if (t == tag) {
      std::memcpy(&bytes[at + 16 + offset], &value, 4);
      found = true;
      break;
    }
    at = (at + 16 + size + 7) & ~std::size_t(7);
  }
  REQUIRE(found);
  std::uint32_t version;
  std::memcpy(&version, &bytes[8], 4);
  const std::uint32_t crc = tree_file_crc(bytes, version);
  std::memcpy(&bytes[36], &crc, 4);
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(bytes.data()),
                                                                std::streamsize(bytes.size()));
}
}  // namespace

// Found by an adversarial review (2026-12-07): a kd tree file whose root box
// (KBND) had been shrunk, with its CRC recomputed, loaded and traced without
// an error while every hit was lost, and `bsprt verify` certified it, because
// the coverage check clipped each triangle to the root box first; NaN bounds
// made verify die of SIGFPE. The flat BSP sections (FHDR) had the same hole in
// the loader (verify caught it there), and verify accepted a flat layout
// version that no traversal can load.
TEST_CASE("tree file: a root box that leaves out a triangle is refused by the loaders and by verify",
          "[regression]") {
  // The cube: its kd-tree and its BSP are single leaves, so no split falls
  // outside a shrunk box and only the box check can see it (the review's case).
  const TriangleSoup soup = load_mesh(bsprt::test::scene_path("cube.obj"));
  const std::string kd_path = bsprt::test::temp_path("regression_kd_box.kd");
  const KdTree kd = build_kd(soup);
  REQUIRE(kd.nodes.size() == 1);
  REQUIRE_NOTHROW(validate_kd_coverage(kd, soup));
  KdTree small = kd;
  small.bounds.lo = {-0.01f, -0.01f, -0.01f};
  small.bounds.hi = {0.01f, 0.01f, 0.01f};
  CHECK_THROWS_WITH(validate_kd_coverage(small, soup), Catch::Contains("sticks out of the root box"));
  write_kd_tree(kd_path, small, soup);
  CHECK_THROWS_WITH(read_kd_tree(kd_path, soup), Catch::Contains("kd-tree root box does not contain triangle"));
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    KdTree b = kd;
    b.bounds.lo.y = bad;
    write_kd_tree(kd_path, b, soup);
    CHECK_THROWS_WITH(read_kd_tree(kd_path, soup), Catch::Contains("kd-tree root box is not finite, or inverted"));
  }
  write_kd_tree(kd_path, kd, soup);
  REQUIRE_NOTHROW(read_kd_tree(kd_path, soup));

  const std::string bsp_path = bsprt::test::temp_path("regression_flat_box.bsp");
  const BspTree exact = build_bsp(soup);
  const FlatBspTree good = flatten_bsp(soup, exact);
  FlatBspTree flat = good;
  write_bsp_file_with_flat(bsp_path, soup, exact, flat);
  REQUIRE_NOTHROW(read_flat_bsp_sections(TreeFileReader(bsp_path), soup));
  flat.bounds.hi.x = 0.0f;  // half the cube
  write_bsp_file_with_flat(bsp_path, soup, exact, flat);
  CHECK_THROWS_WITH(read_flat_bsp_sections(TreeFileReader(bsp_path), soup),
                    Catch::Contains("flat BSP root box does not contain triangle"));
  // FHDR: root_lo[3], root_hi[3], then the layout version at byte 24.
  write_bsp_file_with_flat(bsp_path, soup, exact, good);
  patch_tree_file(bsp_path, kFlatBspHeaderTag, 24, 9);
  CHECK_THROWS_WITH(read_flat_bsp_sections(TreeFileReader(bsp_path), soup), Catch::Contains("layout version 9"));
  CHECK_THROWS_WITH(read_verify_input(bsp_path, soup), Catch::Contains("layout version 9"));
}

// Found by an adversarial review (2026-12-07): `--threads 70000` (and the
// same in the library) crashed inside oneTBB, whose arenas fail above 65535.
TEST_CASE("threads: counts outside [0, kMaxThreads] are a UsageError in every entry point", "[regression]") {
  const TriangleSoup soup = make_default_scene();
  for (const int bad : {-1, kMaxThreads + 1, 70000}) {
    CAPTURE(bad);
    AccelOptions o;
    o.threads = bad;
    CHECK_THROWS_AS(make_tracer("bsp", soup, o), UsageError);
    BspConfig c;
    c.threads = bad;
    CHECK_THROWS_AS(build_bsp(soup, c), UsageError);
  }
  AccelOptions ok;
  ok.threads = kMaxThreads;  // allowed (an arena of at most that many threads)
  CHECK_NOTHROW(make_tracer("kd", soup, ok));
}

// Found by a review of the Python module (2026-12-07): a finite scene spanning
// ±3e38 aborted the process in Embree's SAH builder (an area overflowing to
// inf fails an assertion) for every BVH8 accelerator. The build boxes are now
// scaled by a power of two first; the traversal's boxes are the triangles' own.
TEST_CASE("bvh8: a finite scene wider than the float range of its box areas builds and traces exactly",
          "[regression]") {
  for (const int count : {1, 2}) {  // the review's scene, one triangle; and with a small one behind it
    CAPTURE(count);
    TriangleSoup s;
    add_tri(s, {-3e38f, -3e38f, 0}, {3e38f, -3e38f, 0}, {0, 3e38f, 0});
    if (count == 2) add_tri(s, {-1, -1, 5}, {1, -1, 5}, {0, 1, 5});
    // The float modes' watertight test overflows on corners this large (it
    // misses the big triangle, as `brute` does): they must build and equal the
    // float brute force; the exact modes equal the exact reference.
    const ExactTracer exact(s);
    const BruteForceTracer brute(s);
    for (const std::string name : {"bvh8", "bvh8-float", "bsp-bvh8", "bsp-bvh8-float"}) {
      CAPTURE(name);
      std::unique_ptr<Accelerator> t;
      REQUIRE_NOTHROW(t = make_tracer(name, s, AccelOptions{}));
      const Accelerator& ref = accel_info(name).certified ? static_cast<const Accelerator&>(exact) : brute;
      for (const Ray& r : {ray_of({0, 0, -10}, {0, 0, 1}), ray_of({0, 0, 10}, {0, 0, -1}),
                           ray_of({1e38f, 0, 1}, {0, 0, -1}), ray_of({0.1f, 0.2f, 2}, {0, 0, 1}),
                           ray_of({5e37f, 1e37f, -1}, {0, 0, 1})}) {
        const Hit want = ref.trace(r), got = t->trace(r);
        CHECK(got.prim == want.prim);
        CHECK(got.t == want.t);
      }
    }
  }
}

// Found by a differential review (2026-12-07) on far_1e7's grazing rays: the
// exact reference rounded t by checking CGAL's double estimate and its two
// float neighbours, but a lazy number's estimate comes from its interval and
// was 12 floats off here, so every exact mode reported t 12 ulps from the
// nearest float of the exact t. The rational t is 0.8309395062579203...
TEST_CASE("exact reference: t is the nearest float on a far grazing ray", "[regression]") {
  TriangleSoup s;
  add_tri(s, {10000043.0f, -58.7785301f, 68.8190918f}, {10000035.0f, -51.6121635f, 78.3451691f},
          {10000030.0f, -64.741188f, 70.2309799f});
  const Ray r = ray_of({10000052.0f, -69.82167053222656f, 55.723453521728516f},
                       {-16.0f, 14.334415435791016f, 19.050052642822266f});
  const float want = 0.830939531326294f;  // the nearest float of the rational t, by Python's Fraction
  const ExactTracer exact(s);
  CHECK(exact.trace(r).prim == 0);
  CHECK(exact.trace(r).t == want);
  for (const std::string& name : accel_names()) {
    if (!accel_info(name).certified) continue;
    CAPTURE(name);
    const std::unique_ptr<Accelerator> t = make_tracer(name, s, AccelOptions{});
    const Hit h = t->trace(r);
    CHECK(h.prim == 0);
    CHECK(h.t == want);
  }
}

// Found by a differential review (2026-12-07): with tnear = -inf, the any-hit
// shortcut of the double stage took a hit whose t enclosure reached below
// -FLT_MAX as an occluder, while the nearest-hit query (rightly) missed: the
// line meets this 2^124-wide triangle at t = -2^128, which rounds to -inf.
TEST_CASE("occluded: a hit rounding to -inf does not occlude", "[regression]") {
  TriangleSoup s;
  add_tri(s, {-0x1p123f, -0x1p123f, 0x1p100f}, {0x1p123f, -0x1p123f, 0x1p100f}, {0, 0x1p123f, 0x1p100f});
  const float inf = std::numeric_limits<float>::infinity();
  Ray r = ray_of({0, 0, 0}, {0, 0, -0x1p-28f});
  r.tnear = -inf;
  const ExactTracer exact(s);
  REQUIRE(!exact.trace(r).hit());
  for (const std::string& name : accel_names()) {
    if (name.rfind("embree", 0) == 0) continue;  // Embree refuses tnear < 0 (docs/api.md)
    CAPTURE(name);
    const std::unique_ptr<Accelerator> t = make_tracer(name, s, AccelOptions{});
    CHECK(!t->trace(r).hit());
    CHECK(!t->occluded(r));
  }
}

// Found by a differential review (2026-12-07): one exact mode reported a zero
// t as -0 and another as +0, so the hit files differed byte for byte. The
// exact t has no sign of zero; every exact mode writes +0.
TEST_CASE("exact modes: a hit at t = 0 is +0", "[regression]") {
  TriangleSoup s;
  add_tri(s, {-1, -1, 0}, {3, -1, 0}, {-1, 3, 0});
  for (const Vec3f dir : {Vec3f{0, 0, 1}, Vec3f{0, 0, -1}, Vec3f{0.5f, 0.25f, -1}}) {
    const Ray r = ray_of({0.25f, 0.25f, 0}, dir);
    const ExactTracer exact(s);
    CHECK(exact.trace(r).prim == 0);
    CHECK(!std::signbit(exact.trace(r).t));
    CHECK(exact.trace(r).t == 0);
    for (const std::string& name : accel_names()) {
      if (!accel_info(name).certified) continue;
      CAPTURE(name, dir.z);
      const std::unique_ptr<Accelerator> t = make_tracer(name, s, AccelOptions{});
      const Hit h = t->trace(r);
      CHECK(h.prim == 0);
      CHECK(h.t == 0);
      CHECK(!std::signbit(h.t));
    }
  }
}

// Found by a differential review (2026-12-07): the kd traversal lost hits
// when (s - o) overflowed float for a split or root-box plane s: a plane at
// x = -3.4e38 seen from x = 1e38 along d = -1e8 is crossed at t = 4.4e30, but
// (s - o) = -4.4e38 became -inf, put the crossing at +inf and emptied the
// ray's interval (a shadow-ray shape with tfar = 1e31, and tnear = -5e30
// behind). Such axes now cull nothing (detail::kd_reciprocal), in single rays
// and in packets alike.
TEST_CASE("kd: a crossing whose (s - o) overflows loses no hit", "[regression]") {
  const float M = 3.4e38f;
  for (const int count : {1, 2}) {  // one triangle: the root clip; two: a split between them too
    CAPTURE(count);
    TriangleSoup s;
    add_tri(s, {-M, -1e38f, -1e38f}, {-M, 1e38f, -1e38f}, {-M, 0, 1e38f});
    if (count == 2) add_tri(s, {0, -1, -1}, {0, 1, -1}, {0, 0, 1});
    // The rays pass beside the small triangle (z = 5).
    std::vector<Ray> ahead(16, ray_of({1e38f, 0.5f, 5}, {-1e8f, 0, 0})), behind(16, ray_of({1e38f, 0.5f, 5}, {1e8f, 0, 0}));
    for (Ray& r : ahead) r.tfar = 1e31f;
    for (Ray& r : behind) r.tnear = -5e30f, r.tfar = 0;
    const ExactTracer exact(s);
    const BruteForceTracer brute(s);
    for (const std::string name : {"kd", "kd-float"}) {
      CAPTURE(name);
      const std::unique_ptr<Accelerator> t = make_tracer(name, s, AccelOptions{});
      const Accelerator& ref = accel_info(name).certified ? static_cast<const Accelerator&>(exact) : brute;
      for (const std::vector<Ray>* rays : {&ahead, &behind}) {
        const Hit want = ref.trace((*rays)[0]);
        if (accel_info(name).certified) REQUIRE(want.prim == 0);  // exact: t = +-4.4e30 on the far plane
        CHECK(t->trace((*rays)[0]).prim == want.prim);
        CHECK(t->occluded((*rays)[0]) == want.hit());
        for (const int w : {1, 4, 8, 16}) {
          if (w > 1 && int(detected_isa()) < int(isa_for_width(w))) continue;
          CAPTURE(w);
          std::vector<Hit> got(rays->size());
          t->trace_batch(*rays, got, w);
          for (const Hit& h : got) CHECK((h.prim == want.prim && h.t == want.t));
        }
      }
    }
  }
}

// Found by a differential review (2026-12-07): a scene whose coordinates are
// all near 2^-138 (subnormal floats) ended the exact BSP build in an internal
// error ("three stored planes that do not meet in a point"). CGAL 5.5's
// Mpzf::to_interval returned a point interval 2^128 times too large for a
// homogeneous coordinate near 2^-1300, so a cell vertex (a triangle corner)
// was placed at (1, 2, 3) * 2^-12 instead of 2^-140, and a later split found
// it on the wrong side. exact_enclosure now takes such quotients in Gmpq.
TEST_CASE("bsp build: a scene with subnormal coordinates builds, verifies and traces exactly", "[regression]") {
  const float grid[12][3] = {{0, 5, 1}, {1, 5, 0}, {1, 6, 2}, {3, 4, 2},   {3, 5, 2}, {4, 5, 2},
                             {1, 2, 3}, {1, 2, 5}, {2, 2, 5}, {2, 1, 4.5f}, {4, 1, 6.5f}, {2, 1, 4}};
  for (const int e : {0, -140}) {  // the same scene at scale 1 always built
    CAPTURE(e);
    TriangleSoup s;
    for (const auto& g : grid) s.vertices.push_back({std::ldexp(g[0], e), std::ldexp(g[1], e), std::ldexp(g[2], e)});
    s.triangles = {{5, 4, 3}, {6, 8, 7}, {2, 1, 0}, {9, 10, 11}};
    classify_degenerate(s);
    BspTree exact_tree;
    REQUIRE_NOTHROW(exact_tree = build_bsp(s));
    const std::string path = bsprt::test::temp_path("regression_subnormal.bsp");
    write_bsp_file_with_flat(path, s, exact_tree, flatten_bsp(s, exact_tree));
    const VerifyReport r = verify_bsp(s, read_verify_input(path, s));
    INFO((r.failure ? r.failure->describe() : std::string("ok")));
    CHECK(r.certified);
    // Rays from points around the scene to every corner and triangle centre.
    const ExactTracer exact(s);
    const std::unique_ptr<Accelerator> bsp = make_tracer("bsp", s, AccelOptions{});
    const float from[4][3] = {{-1, -1, -1}, {7, 8, 9}, {2.5f, 3, -4}, {-3, 9, 2}};
    int hits = 0;
    for (const auto& f : from)
      for (std::uint32_t t = 0; t < s.size(); ++t)
        for (int k = 0; k <= 3; ++k) {
          const Vec3f o{std::ldexp(f[0], e), std::ldexp(f[1], e), std::ldexp(f[2], e)};
          const Vec3f target = k < 3 ? s.corner(t, k)
                                     : (s.corner(t, 0) + s.corner(t, 1) + s.corner(t, 2)) * (1.0f / 3.0f);
          const Ray ray = ray_of(o, target - o);
          const Hit want = exact.trace(ray), got = bsp->trace(ray);
          hits += want.hit();
          CHECK(got.prim == want.prim);
          CHECK(got.t == want.t);
        }
    CHECK(hits > 40);  // most of the 64 rays hit something
  }
}

// Found by an adversarial review of the verifier (2026-12-07): `bsprt verify`
// certified BSP files that `bsprt trace --tree` then refused (an unused extra
// entry in the flat leaf lists, normals scaled by 1/2, ...). The certificate
// checks the geometry, independently of the loaders; CERTIFIED now also means
// that the tracers load the file (bsp_tree_load_problem).
TEST_CASE("verify: a certified BSP file the tracers refuse is not certified", "[regression]") {
  const TriangleSoup soup = make_default_scene();
  const BspTree exact = build_bsp(soup);
  const FlatBspTree good = flatten_bsp(soup, exact);
  const std::string path = bsprt::test::temp_path("regression_verify_loadable.bsp");
  write_bsp_file_with_flat(path, soup, exact, good);
  REQUIRE(bsp_tree_load_problem(soup, std::make_shared<const TreeFileReader>(path)).empty());
  CliRun ok = bsprt_cli("verify default " + path + " --threads 1");
  CHECK(ok.status == 0);
  CHECK(ok.output.find("CERTIFIED") != std::string::npos);

  FlatBspTree extra = good;
  extra.prims.push_back(0);  // listed by no leaf: the geometry is untouched
  write_bsp_file_with_flat(path, soup, exact, extra);
  REQUIRE(verify_bsp(soup, read_verify_input(path, soup)).certified);  // the geometric certificate alone
  CHECK(!bsp_tree_load_problem(soup, std::make_shared<const TreeFileReader>(path)).empty());
  CliRun bad = bsprt_cli("verify default " + path + " --threads 1");
  CHECK(bad.status == 1);
  CHECK(bad.output.find("CERTIFIED") == std::string::npos);
  CHECK(bad.output.find("the tree is exact, but bsprt's tracers refuse the file") != std::string::npos);
  AccelOptions from_file;
  from_file.tree_path = path;
  CHECK_THROWS(make_tracer("bsp", soup, from_file));  // what `bsprt trace --tree` runs
}

// Found by a differential review (2026-12-07): a finite scene near 3e38
// failed in the BSP's flattening with "plane bound is not finite (scene
// coordinates too large?)", while kd, bvh8 and the exact modes traced it. The
// limit is real (float planes); the message now says what to use instead.
TEST_CASE("bsp: a scene near the float range's end is refused with a message that names the accelerators that take it",
          "[regression]") {
  TriangleSoup s = load_mesh(bsprt::test::scene_path("cube.obj"));
  for (Vec3f& v : s.vertices) v = v * 2e37f + Vec3f{3e38f, 3e38f, 3e38f};
  classify_degenerate(s);
  CHECK_THROWS_WITH(make_tracer("bsp", s, AccelOptions{}), Catch::Contains("trace it with kd, bvh8 or brute-certified"));
  const ExactTracer exact(s);
  const Ray r = ray_of({0, 0, 0}, {1, 1, 1});
  REQUIRE(exact.trace(r).hit());
  for (const char* name : {"kd", "bvh8", "brute-certified"}) {
    CAPTURE(name);
    const Hit h = make_tracer(name, s, AccelOptions{})->trace(r);
    CHECK(h.prim == exact.trace(r).prim);
    CHECK(h.t == exact.trace(r).t);
  }
}
