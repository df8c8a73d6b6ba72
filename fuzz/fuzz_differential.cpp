// Differential libFuzzer harness: bytes -> a small triangle soup (<= 12
// triangles over a pool of 8 vertices whose coordinates come from a small grid
// of floats, so duplicates, shared edges, coplanar and degenerate triangles are
// common) and up to 16 rays aimed at pool vertices and edge points, some made
// special (a direction component ±0, subnormal, huge, infinite or NaN; the
// direction scaled by 2^-100 or 2^100; a segment starting behind the origin).
// Builds brute, kd, bvh8, bvh8-float, bsp-float, bsp (exact leaves), bsp-top-float
// and bsp-top (box tops over one-slot subtrees), bsp-bvh8 (BVH8 tops over pieces of
// one and of eight slots) and the exact reference and traps when
//   - kd, bvh8, bsp, bsp-top or bsp-bvh8 (exact leaves) differ from the exact reference (lost,
//     extra, farther or nearer; a tie on another triangle at the same t is
//     allowed), or
//   - kd, bsp or bsp-top differ from brute force beyond ties: all run the same
//     float watertight test, so a tree may only change which of several
//     triangles at the same t is reported, or
//   - kd or bsp packets (every width this CPU runs) differ from the same
//     tree's single rays in any bit of any hit or in any counter: the packet
//     kernels promise the single-ray sequence of nodes and leaves per lane, or
//   - bvh8-float's plain x86-64 kernel differs from its AVX2 or AVX-512 kernel in any bit,
//     or a kernel's batch loop from its single rays.
// (bvh8-float and bsp-bvh8-float are not compared with brute force: their boxes are exact, so a
// float hit on a triangle whose box the exact ray just misses is not found;
// docs/bvh8.md.)
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "builder/accel_factory.h"
#include "bsprt/compare.h"
#include "robust/degenerate.h"
#include "traverse/bsp/bsp_traverse.h"
#include "traverse/bvh/bvh8_traverse.h"
#include "traverse/simd/cpu_features.h"

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

/// Values a direction component may be replaced by: signed zeros (the ray
/// stays in a slab), subnormals (flushed slopes), huge and infinite magnitudes
/// and NaN (invalid rays: every tracer must report a miss).
constexpr float kSpecial[8] = {0.0f, -0.0f, 1e-40f, -1e-40f, 0x1p70f, -3e38f,
                               std::numeric_limits<float>::infinity(),
                               std::numeric_limits<float>::quiet_NaN()};

/// Half of the rays stay ordinary (mode 0-3); the others get one change.
void make_special(bsprt::Ray& r, std::uint8_t e) {
  const int axis = (e >> 3) % 3;
  switch (e & 7) {
    case 4: r.dir[axis] = kSpecial[(e >> 5) & 1]; break;   // axis-parallel component
    case 5: r.dir[axis] = kSpecial[(e >> 5) & 7]; break;   // any special value
    case 6: r.dir = r.dir * ((e & 32) ? 0x1p-100f : 0x1p100f); break;  // tiny or huge direction
    case 7: r.tnear = (e & 32) ? -1e30f : -0.5f; r.tfar = (e & 64) ? 0.75f : r.tfar; break;
    default: break;
  }
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
    make_special(r, in.next());
    rays.push_back(r);
  }
  return rays;
}

std::unique_ptr<bsprt::Accelerator> make(const std::string& accel, const bsprt::TriangleSoup& s,
                                     std::uint32_t top_slots = 1024) {
  bsprt::AccelOptions o;
  o.threads = 1;
  o.top_slots = top_slots;
  o.bsp_packets = bsprt::BspPackets::Always;  // the packet kernel on every packet, incoherent ones too
  return bsprt::make_tracer(accel, s, o);
}

std::vector<bsprt::Hit> trace(const bsprt::Accelerator& t, std::span<const bsprt::Ray> rays) {
  std::vector<bsprt::Hit> hits;
  for (const bsprt::Ray& r : rays) hits.push_back(t.trace(r));
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

/// Packets of every width this CPU runs equal the same tracer's single rays bit
/// for bit, hits and counters.
void expect_packets_equal(const char* accel, const bsprt::Accelerator& t, std::span<const bsprt::Ray> rays) {
  std::vector<bsprt::Hit> single(rays.size());
  bsprt::RayCounters cs;
  t.trace_batch(rays, single, 1, &cs);
  for (int w : {4, 8, 16}) {
    if (int(bsprt::detected_isa()) < int(bsprt::isa_for_width(w))) continue;
    std::vector<bsprt::Hit> packed(rays.size());
    bsprt::RayCounters cp;
    t.trace_batch(rays, packed, w, &cp);
    for (std::size_t i = 0; i < rays.size(); ++i)
      if (std::memcmp(&single[i], &packed[i], sizeof(bsprt::Hit)) != 0) {
        std::fprintf(stderr, "%s packets of %d: ray %zu: single t=%a prim=%u, packet t=%a prim=%u\n", accel,
                     w, i, double(single[i].t), single[i].prim, double(packed[i].t), packed[i].prim);
        __builtin_trap();
      }
    // Uncounted: exact leaves run in the packet kernels only then (counted runs go single).
    std::vector<bsprt::Hit> fast(rays.size());
    t.trace_batch(rays, fast, w, nullptr);
    for (std::size_t i = 0; i < rays.size(); ++i)
      if (std::memcmp(&single[i], &fast[i], sizeof(bsprt::Hit)) != 0) {
        std::fprintf(stderr, "%s uncounted packets of %d: ray %zu differs from single rays\n", accel, w, i);
        __builtin_trap();
      }
    if (cp.rays != cs.rays || cp.kd_node_visits != cs.kd_node_visits || cp.bsp_node_visits != cs.bsp_node_visits ||
        cp.leaf_visits != cs.leaf_visits || cp.triangle_tests != cs.triangle_tests) {
      std::fprintf(stderr, "%s packets of %d: counters differ from single rays\n", accel, w);
      __builtin_trap();
    }
  }
}

/// The BVH8's plain x86-64 kernel equals its AVX2 and AVX-512 kernels bit for bit,
/// and each kernel's batch loop (trace_batch) equals its single rays.
void expect_bvh8_kernels_equal(bsprt::Accelerator& t, std::span<const bsprt::Ray> rays) {
  auto& bvh = dynamic_cast<bsprt::Bvh8Tracer&>(t);
  bvh.set_kernel_isa(bsprt::Isa::Scalar);
  const std::vector<bsprt::Hit> base = trace(bvh, rays);
  const auto expect_same = [&](const char* what, bsprt::Isa isa, const std::vector<bsprt::Hit>& got) {
    for (std::size_t i = 0; i < rays.size(); ++i)
      if (std::memcmp(&base[i], &got[i], sizeof(bsprt::Hit)) != 0) {
        std::fprintf(stderr, "bvh8-float %s %s: ray %zu: base t=%a prim=%u, got t=%a prim=%u\n",
                     bsprt::isa_name(isa).c_str(), what, i, double(base[i].t), base[i].prim, double(got[i].t),
                     got[i].prim);
        __builtin_trap();
      }
  };
  for (const bsprt::Isa isa : {bsprt::Isa::Scalar, bsprt::Isa::Avx2, bsprt::Isa::Avx512}) {
    if (int(bsprt::detected_isa()) < int(isa)) continue;
    bvh.set_kernel_isa(isa);
    if (isa != bsprt::Isa::Scalar) expect_same("single rays", isa, trace(bvh, rays));  // Scalar's are `base`
    std::vector<bsprt::Hit> batch(rays.size());
    bvh.trace_batch(rays, batch);
    expect_same("batch", isa, batch);
  }
}

/// The interleaved single-ray kernel equals the sequential one bit for bit.
void expect_interleaved_equal(bsprt::Accelerator& t, std::span<const bsprt::Ray> rays) {
  auto& bsp = dynamic_cast<bsprt::BspTracer&>(t);
  std::vector<bsprt::Hit> seq(rays.size()), inter(rays.size());
  bsp.set_single_rays(bsprt::BspSingleRays::Sequential);
  bsp.trace_batch(rays, seq, 1);
  bsp.set_single_rays(bsprt::BspSingleRays::Interleaved);
  bsp.trace_batch(rays, inter, 1);
  bsp.set_single_rays(bsprt::BspSingleRays::Auto);
  for (std::size_t i = 0; i < rays.size(); ++i)
    if (std::memcmp(&seq[i], &inter[i], sizeof(bsprt::Hit)) != 0) {
      std::fprintf(stderr, "bsp interleaved: ray %zu: sequential t=%a prim=%u, interleaved t=%a prim=%u\n", i,
                   double(seq[i].t), seq[i].prim, double(inter[i].t), inter[i].prim);
      __builtin_trap();
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Reader in{data, size};
  const bsprt::TriangleSoup soup = make_soup(in);
  const std::vector<bsprt::Ray> rays = make_rays(in, soup);
  if (rays.empty()) return 0;
  const std::vector<bsprt::Hit> exact = trace(*make("exact", soup), rays);
  const std::vector<bsprt::Hit> brute = trace(*make("brute", soup), rays);
  expect_agree("bsp vs exact", exact, trace(*make("bsp", soup), rays));
  // Box tops of one-slot subtrees: every leaf under its own box, the deepest top.
  expect_agree("bsp-top vs exact", exact, trace(*make("bsp-top", soup, 1), rays));
  expect_agree("bsp-top-float vs brute", brute, trace(*make("bsp-top-float", soup, 1), rays));
  expect_agree("kd vs exact", exact, trace(*make("kd", soup), rays));
  {
    const auto bvh8 = make("bvh8", soup);
    expect_agree("bvh8 vs exact", exact, trace(*bvh8, rays));
    std::vector<bsprt::Hit> batch(rays.size());
    bvh8->trace_batch(rays, batch);
    expect_agree("bvh8 batch vs exact", exact, batch);
  }
  expect_agree("bsp-bvh8 vs exact", exact, trace(*make("bsp-bvh8", soup, 1), rays));
  expect_agree("bsp-bvh8 (8 slots) vs exact", exact, trace(*make("bsp-bvh8", soup, 8), rays));
  expect_bvh8_kernels_equal(*make("bvh8-float", soup), rays);
  expect_packets_equal("kd", *make("kd", soup), rays);  // exact leaves in the packet kernels
  const auto kd = make("kd-float", soup), bsp = make("bsp-float", soup);
  expect_agree("kd-float vs brute", brute, trace(*kd, rays));
  expect_agree("bsp-float vs brute", brute, trace(*bsp, rays));
  expect_packets_equal("kd-float", *kd, rays);
  expect_packets_equal("bsp-float", *bsp, rays);
  expect_interleaved_equal(*bsp, rays);
  expect_packets_equal("bsp", *make("bsp", soup), rays);  // exact leaves in the packet kernels
  return 0;
}
