// Differential libFuzzer harness: bytes -> a small triangle soup (<= 12
// triangles over a pool of 8 vertices whose coordinates come from a small grid
// of floats, so duplicates, shared edges, coplanar and degenerate triangles are
// common) and up to 16 rays aimed at pool vertices and edge points. Builds
// brute, kd, bsp, bsp-certified and the exact reference and traps when
//   - bsp-certified differs from the exact reference (lost, extra, farther or
//     nearer; a tie on another triangle at the same t is allowed), or
//   - kd or bsp differ from brute force beyond ties: all three run the same
//     float watertight test, so a tree may only change which of several
//     triangles at the same t is reported.
#include <cstdint>
#include <cstdio>
#include <span>
#include <vector>

#include "builder/accel_factory.h"
#include "geometry/hit_compare.h"
#include "robust/degenerate.h"

namespace {

/// The coordinate grid: small integers, halves, values one ulp apart, and a
/// value (0.1f) that is not dyadic.
constexpr float kGrid[8] = {0.0f, 1.0f, -1.0f, 0.5f, 2.0f, 0.1f, 1.00000012f, 3.0f};

struct Reader {
  const std::uint8_t* p;
  std::size_t n;
  std::uint8_t next() {
    if (n == 0) return 0;
    --n;
    return *p++;
  }
  bool empty() const { return n == 0; }
};

bsprt::TriangleSoup make_soup(Reader& in) {
  bsprt::TriangleSoup s;
  for (int v = 0; v < 8; ++v) {
    const float x = kGrid[in.next() % 8], y = kGrid[in.next() % 8], z = kGrid[in.next() % 8];
    s.vertices.push_back({x, y, z});
  }
  const int n = 1 + in.next() % 12;
  for (int t = 0; t < n; ++t)
    s.triangles.push_back({std::uint32_t(in.next() % 8), std::uint32_t(in.next() % 8), std::uint32_t(in.next() % 8)});
  bsprt::classify_degenerate(s);
  return s;
}

std::vector<bsprt::Ray> make_rays(Reader& in, const bsprt::TriangleSoup& s) {
  std::vector<bsprt::Ray> rays;
  while (!in.empty() && rays.size() < 16) {
    bsprt::Ray r;
    const std::uint8_t a = in.next(), b = in.next(), c = in.next(), d = in.next();
    r.org = {kGrid[a % 8] * 3.0f - 0.25f, kGrid[b % 8] * 3.0f + 0.125f, kGrid[c % 8] * 3.0f - 1.0f};
    const bsprt::Vec3f p = s.vertices[d % 8], q = s.vertices[(d / 8) % 8];
    const float w = float(d / 64) / 4.0f;  // 0, 1/4, 1/2, 3/4 of the way to q: vertices and edge points
    r.dir = (p + (q - p) * w) - r.org;
    rays.push_back(r);
  }
  return rays;
}

std::vector<bsprt::Hit> trace(const std::string& accel, const bsprt::TriangleSoup& s, std::span<const bsprt::Ray> rays) {
  bsprt::AccelOptions o;
  o.threads = 1;
  const auto t = bsprt::make_tracer(accel, s, o);
  std::vector<bsprt::Hit> hits;
  for (const bsprt::Ray& r : rays) hits.push_back(t->trace(r));
  return hits;
}

void expect_agree(const char* what, std::span<const bsprt::Hit> ref, std::span<const bsprt::Hit> got) {
  const bsprt::HitComparison c = bsprt::compare_hits(ref, got);
  if (c.agrees()) return;
  std::fprintf(stderr, "%s: lost %llu extra %llu farther %llu nearer %llu (first bad ray %llu)\n", what,
               (unsigned long long)c.lost, (unsigned long long)c.extra, (unsigned long long)c.farther,
               (unsigned long long)c.nearer, (unsigned long long)c.first_bad_ray);
  __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Reader in{data, size};
  const bsprt::TriangleSoup soup = make_soup(in);
  const std::vector<bsprt::Ray> rays = make_rays(in, soup);
  if (rays.empty()) return 0;
  const std::vector<bsprt::Hit> exact = trace("exact", soup, rays);
  const std::vector<bsprt::Hit> brute = trace("brute", soup, rays);
  expect_agree("bsp-certified vs exact", exact, trace("bsp-certified", soup, rays));
  expect_agree("kd vs brute", brute, trace("kd", soup, rays));
  expect_agree("bsp vs brute", brute, trace("bsp", soup, rays));
  return 0;
}
