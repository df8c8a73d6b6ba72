// Flat BSP traversal (issue 5): hits equal brute force with no lost hit on
// shared meshes, stiff generated scenes, translated and scaled scenes and
// special rays, plainly and under box tops (bsp_boxtop.h); packets equal single rays bit for bit (hits and counters);
// rays from inside closed meshes never escape; the flat sections round-trip.
#include <catch2/catch.hpp>

#include <algorithm>
#include <fmt/core.h>

#include <bit>
#include <cmath>
#include <limits>
#include <chrono>
#include <cstring>
#include <memory>
#include <cstdlib>
#include <map>
#include <random>

#include "bsp_test_util.h"
#include "builder/accel_factory.h"
#include "builder/bsp/bsp_flat_io.h"
#include "builder/kd/kd_build.h"
#include "geometry/scenes/default_scene.h"
#include "bsprt/compare.h"
#include "geometry/io/load_mesh.h"
#include "geometry/scenes/ray_gen.h"
#include "robust/exact_tracer.h"
#include "traverse/bsp/bsp_kernel.h"
#include "test_util.h"
#include "traverse/simd/cpu_features.h"
#include "traverse/embree/box_top_build.h"
#include "traverse/kd/kd_traverse.h"

using namespace bsprt;
using namespace bsprt::test;

namespace {

TriangleSoup transformed(TriangleSoup s, float scale, Vec3f shift) {
  for (Vec3f& v : s.vertices) v = v * scale + shift;
  return s;
}

/// Coplanar stack: overlapping triangles in one plane z = 0 (several copies,
/// both windings), plus near-parallel layers 1e-4 apart and a slanted copy.
TriangleSoup make_coplanar_stack() {
  TriangleSoup s;
  const auto tri = [&](Vec3f a, Vec3f b, Vec3f c) {
    const std::uint32_t i = std::uint32_t(s.vertices.size());
    s.vertices.insert(s.vertices.end(), {a, b, c});
    s.triangles.push_back({i, i + 1, i + 2});
  };
  for (int k = 0; k < 4; ++k) {
    const float z = k < 2 ? 0.0f : float(k - 1) * 1e-4f;
    tri({0, 0, z}, {1, 0, z}, {0, 1, z});
    tri({1, 1, z}, {0, 1, z}, {1, 0, z});
    tri({0.25f, 0.25f, z}, {0.75f, 0.25f, z}, {0.25f, 0.75f, z});
    tri({0, 0, z}, {0, 1, z}, {1, 0, z});  // opposite winding duplicate
  }
  tri({0, 0, 0}, {1, 0, 0.3f}, {0, 1, 0.7f});
  tri({1, 1, 1.0f}, {0, 1, 0.7f}, {1, 0, 0.3f});
  return s;
}

/// Slivers: long thin triangles meeting at shared edges, slightly slanted.
TriangleSoup make_slivers() {
  TriangleSoup s;
  for (int i = 0; i < 40; ++i) {
    const float x = float(i) * 0.05f, h = 1e-5f * float(1 + i % 7);
    const std::uint32_t b = std::uint32_t(s.vertices.size());
    s.vertices.insert(s.vertices.end(), {{x, 0, 0.01f * x}, {x + 0.05f, 0, 0.01f * x},
                                         {x + 0.025f, 3.0f, h}, {x + 0.025f, -3.0f, -h}});
    s.triangles.push_back({b, b + 1, b + 2});
    s.triangles.push_back({b + 1, b, b + 3});
  }
  return s;
}

std::vector<Ray> all_ray_sets(const TriangleSoup& soup, std::size_t n, std::uint64_t seed) {
  std::vector<Ray> rays;
  for (RaySetKind k : {RaySetKind::Primary, RaySetKind::Random, RaySetKind::Vertex, RaySetKind::Edge}) {
    const std::vector<Ray> r = make_rays(k, soup, n, seed);
    rays.insert(rays.end(), r.begin(), r.end());
  }
  return rays;
}

/// `flat` traced plainly (top_slots 0) or under a box top of subtrees of at
/// most `top_slots` slots.
BspTracer make_bsp(const FlatBspTree& flat, const TriangleSoup& soup, std::uint32_t top_slots) {
  BspTracer t(flat, soup);
  if (top_slots > 0) add_box_top(t, top_slots);
  return t;
}

/// BSP (certified) vs brute force: no lost hit, no farther hit; plainly and
/// under box tops of 1-slot (every leaf its own box) and 64-slot subtrees.
void check_scene(const std::string& name, TriangleSoup soup, std::size_t n = 600) {
  const BspScene s = build_bsp_scene(std::move(soup));
  const std::vector<Ray> rays = all_ray_sets(s.soup, n, 7);
  for (std::uint32_t top : {0u, 1u, 64u}) {
    const BspTracer tracer = make_bsp(s.flat, s.soup, top);
    const Comparison c = compare_with_brute(s.soup, tracer, rays);
    INFO(name << " (box top slots " << top << "): " << c.rays << " rays, " << c.hits << " hits, " << c.ties
              << " ties, " << c.float_only << " float-only, lost " << c.lost << ", farther " << c.farther
              << ", impossible " << c.impossible << "; first: " << c.first_failure);
    CHECK(c.ok());
    CHECK(c.hits > 0);
  }
}

}  // namespace

TEST_CASE("flat BSP node layout and a hand-built tree", "[bsp]") {
  STATIC_REQUIRE(sizeof(FlatBspNode) == 16);
  // Two triangles at x = -1 and x = +1 separated by the slanted plane x + y = 0.
  TriangleSoup soup;
  soup.vertices = {{-1, -1, -1}, {-1, 1, -1}, {-1, 0, 1}, {1, -1, -1}, {1, 1, -1}, {1, 0, 1}};
  soup.triangles = {{0, 1, 2}, {3, 4, 5}};
  classify_degenerate(soup);
  FlatBspTree t;
  t.bounds = soup.bounds();
  t.triangle_count = 2;
  const float h = float(1.0 / std::sqrt(2.0));
  const float n[3] = {h, h, 0.0f};
  t.nodes = {FlatBspNode::make_plane_head(n, 3), FlatBspNode::make_plane_tail(0.0f, 1e-6f),
             FlatBspNode::make_leaf(0, 1), FlatBspNode::make_leaf(1, 1)};
  t.prims = {0, 1};
  REQUIRE_NOTHROW(t.validate());
  // (The hand-built tree is not certified for this geometry: triangle 0 crosses
  // the plane. Rays are chosen so that the answer is still unambiguous.)
  const BspTracer tracer(t, soup);
  RayCounters c;
  const Hit a = tracer.trace(Ray{{-3, -0.5f, 0}, 0, {1, 0, 0}}, &c);
  CHECK(a.prim == 0);
  CHECK(a.t == 2.0f);
  const Hit b = tracer.trace(Ray{{3, 0.5f, 0}, 0, {-1, 0, 0}}, &c);
  CHECK(b.prim == 1);
  CHECK(c.rays == 2);
  CHECK(c.bsp_node_visits == 2);
  FlatBspTree bad = t;
  bad.nodes[0].bits = (2u << 3) | 3u;  // second child == first child
  CHECK_THROWS(bad.validate());
}

namespace {

std::uint64_t flat_refs(const FlatBspTree& f, std::uint32_t i) {
  const FlatBspNode& n = f.nodes[i];
  return n.is_leaf() ? n.prim_count() : flat_refs(f, i + n.slots()) + flat_refs(f, n.second_child());
}

/// Walks flat node fi (listing triangles) and compact node ci together: same
/// kinds, every float bit for bit, same leaf ranges, and a child is absent
/// from the compact tree exactly when its flat subtree lists no triangle.
void check_compact_node(const FlatBspTree& f, const CompactBspTree& c, std::uint32_t fi, std::uint32_t ci,
                        std::size_t& reached_slots, std::size_t& refs) {
  const FlatBspNode& fn = f.nodes[fi];
  REQUIRE(ci < c.slots.size());
  const CompactBspSlot& cn = c.slots[ci];
  REQUIRE(cn.kind_bits() == (fn.bits & 7u));
  reached_slots += cn.slots();
  if (fn.is_leaf()) {
    CHECK(cn.prim_offset() == fn.prim_offset());
    CHECK(cn.prim_count() == fn.prim_count());
    CHECK(cn.prim_count() > 0);
    refs += cn.prim_count();
    return;
  }
  if (fn.is_plane()) {
    for (int k = 0; k < 3; ++k)
      CHECK(std::bit_cast<std::uint32_t>(cn.plane_normal(k)) == std::bit_cast<std::uint32_t>(fn.normal(k)));
    CHECK(std::bit_cast<std::uint32_t>(cn.plane_d()) == f.nodes[fi + 1].bits);
    CHECK(std::bit_cast<std::uint32_t>(cn.plane_eps()) == f.nodes[fi + 1].w[0]);
  } else {
    CHECK(std::bit_cast<std::uint32_t>(cn.split()) == fn.w[0]);
  }
  const std::uint32_t ff = fi + fn.slots(), fs = fn.second_child();
  const bool fe = flat_refs(f, ff) == 0, se = flat_refs(f, fs) == 0;
  CHECK(cn.first_empty() == fe);
  CHECK(cn.second_empty() == se);
  if (!fe) check_compact_node(f, c, ff, ci + cn.slots(), reached_slots, refs);
  if (!se) check_compact_node(f, c, fs, cn.second_child(), reached_slots, refs);
}

}  // namespace

TEST_CASE("compact traversal layout keeps every float and drops only empty subtrees", "[bsp]") {
  STATIC_REQUIRE(sizeof(CompactBspSlot) == 8);
  for (TriangleSoup soup : {load_mesh(scene_path("suzanne.obj")), make_default_scene(), make_coplanar_stack()}) {
    const BspScene s = build_bsp_scene(std::move(soup));
    const CompactBspTree c = compact_bsp(s.flat);
    const FlatBspStats fs = flat_bsp_stats(s.flat);
    REQUIRE(fs.empty_leaves > 0);  // the case this layout exists for
    std::size_t reached = 0, refs = 0;
    check_compact_node(s.flat, c, 0, 0, reached, refs);
    CHECK(reached == c.slots.size());  // no slot left unreached
    CHECK(refs == s.flat.prims.size());
    CHECK(c.slots.size() * sizeof(CompactBspSlot) < s.flat.nodes.size() * sizeof(FlatBspNode));  // fewer bytes
  }
  // A subtree of empty leaves collapses into its parent's flag; a tree without
  // triangles is one empty root leaf.
  FlatBspTree t;
  t.bounds = {{0, 0, 0}, {1, 1, 1}};
  t.triangle_count = 1;
  t.nodes = {FlatBspNode::make_kd(0, 0.5f, 4), FlatBspNode::make_kd(1, 0.5f, 3), FlatBspNode::make_leaf(0, 0),
             FlatBspNode::make_leaf(0, 0), FlatBspNode::make_leaf(0, 1)};
  t.prims = {0};
  REQUIRE_NOTHROW(t.validate());
  const CompactBspTree c = compact_bsp(t);
  REQUIRE(c.slots.size() == 2);
  CHECK(c.slots[0].first_empty());
  CHECK(!c.slots[0].second_empty());
  CHECK(c.slots[0].second_child() == 1);
  CHECK(c.slots[1].is_leaf());
  CHECK(c.slots[1].prim_count() == 1);
  t.nodes[4] = FlatBspNode::make_leaf(0, 0);
  t.prims.clear();
  const CompactBspTree e = compact_bsp(t);
  REQUIRE(e.slots.size() == 1);
  CHECK(e.slots[0].is_leaf());
  CHECK(e.slots[0].prim_count() == 0);
}

TEST_CASE("BSP hits equal brute force on shared meshes", "[bsp]") {
  for (const char* name : {"cube.obj", "suzanne.obj", "utah-teapot.obj", "stiff_degenerated.obj",
                           "stiff_planexy.off", "stiff_cube_with_fold.ply", "stiff_sliver_tet.ply"})
    check_scene(name, load_mesh(scene_path(name)));
}

TEST_CASE("BSP hits equal brute force on the bunny", "[bsp]") {
  check_scene("stanford-bunny.obj", load_mesh(scene_path("stanford-bunny.obj")), 300);
}

TEST_CASE("BSP hits equal brute force on stiff generated scenes", "[bsp]") {
  check_scene("icosphere", make_icosphere({0.1f, 0.2f, 0.3f}, 1.0f, 3));
  check_scene("torus knot", make_torus_knot({0, 0, 0}, 1.0f, 0.3f, 2, 3, 96, 12));
  check_scene("ground", make_ground({0, 0, 0}, 2.0f, 8));
  check_scene("coplanar stack", make_coplanar_stack());
  check_scene("slivers", make_slivers());
  check_scene("default scene", make_default_scene(), 300);
}

TEST_CASE("BSP hits equal brute force on translated and scaled scenes", "[bsp]") {
  const TriangleSoup suzanne = load_mesh(scene_path("suzanne.obj"));
  const TriangleSoup sphere = make_icosphere({0, 0, 0}, 1.0f, 3);
  check_scene("suzanne + 1e5", transformed(suzanne, 1.0f, {1e5f, -1e5f, 1e5f}));
  check_scene("suzanne * 1e-4", transformed(suzanne, 1e-4f, {0, 0, 0}));
  check_scene("icosphere + 1e5", transformed(sphere, 1.0f, {1e5f, 1e5f, 1e5f}));
  check_scene("icosphere * 1e-4 + 1e5", transformed(sphere, 1e-4f, {0, 0, 1e5f}));
}

namespace {
/// Box of child i of a box-top node.
Box3f child_box(const BoxTopNode& n, int i) {
  Box3f b;
  for (int k = 0; k < 3; ++k) b.lo[k] = n.lo[k][i], b.hi[k] = n.hi[k][i];
  return b;
}
bool contains(const Box3f& outer, const Box3f& inner) {
  for (int k = 0; k < 3; ++k)
    if (inner.lo[k] < outer.lo[k] || inner.hi[k] > outer.hi[k]) return false;
  return true;
}
/// Subtree slots under top node `i`, checking that every child box holds the
/// boxes below it; `box_of` maps a subtree slot to its box.
void collect(const BoxTop& top, std::uint32_t i, const std::map<std::uint32_t, Box3f>& box_of,
             std::vector<std::uint32_t>& out, std::size_t& bad_nesting) {
  const BoxTopNode& n = top.nodes[i];
  for (int c = 0; c < 4; ++c) {
    if (n.child[c] == BoxTopNode::kNone) continue;
    if (n.child[c] & BoxTopNode::kSubtree) {
      const std::uint32_t slot = n.child[c] & ~BoxTopNode::kSubtree;
      out.push_back(slot);
      if (!box_of.count(slot) || !contains(child_box(n, c), box_of.at(slot))) ++bad_nesting;
      continue;
    }
    std::vector<std::uint32_t> below;
    collect(top, n.child[c], box_of, below, bad_nesting);
    for (std::uint32_t slot : below)
      if (!box_of.count(slot) || !contains(child_box(n, c), box_of.at(slot))) ++bad_nesting;
    out.insert(out.end(), below.begin(), below.end());
  }
}
/// Leaves listing triangles in the compact subtree at slot i.
void leaves_under(const CompactBspTree& t, std::uint32_t i, std::vector<std::uint32_t>& out) {
  const CompactBspSlot& n = t.slots[i];
  if (n.is_leaf()) {
    if (n.prim_count() > 0) out.push_back(i);
    return;
  }
  if (!n.first_empty()) leaves_under(t, i + n.slots(), out);
  if (!n.second_empty()) leaves_under(t, n.second_child(), out);
}
}  // namespace

TEST_CASE("box top: every leaf under exactly one box and boxes nest", "[bsp]") {
  const BspScene s = build_bsp_scene(load_mesh(scene_path("suzanne.obj")));
  const BspTracer plain(s.flat, s.soup);
  std::vector<std::uint32_t> all_leaves;
  leaves_under(plain.compact(), 0, all_leaves);
  REQUIRE(all_leaves.size() > 100);
  for (std::uint32_t slots : {1u, 8u, 64u, 1024u, CompactBspSlot::kMaxIndex}) {
    const std::vector<BspSubtreeBox> boxes = plain.subtree_boxes(slots);
    const BoxTop top = build_box_top(boxes);
    INFO("slots " << slots << ", " << boxes.size() << " subtrees, " << top.nodes.size() << " top nodes");
    REQUIRE(!boxes.empty());
    CHECK(top.subtrees == boxes.size());
    if (slots == 1) CHECK(boxes.size() == all_leaves.size());  // every leaf its own box
    if (slots == CompactBspSlot::kMaxIndex) CHECK(boxes.size() == 1);  // the root subtree
    std::map<std::uint32_t, Box3f> box_of;
    for (const BspSubtreeBox& b : boxes) box_of[b.slot] = b.box;
    CHECK(box_of.size() == boxes.size());
    // The top lists every subtree once, each child box holding the boxes under it.
    std::vector<std::uint32_t> listed;
    std::size_t bad_nesting = 0;
    collect(top, 0, box_of, listed, bad_nesting);
    CHECK(bad_nesting == 0);
    std::sort(listed.begin(), listed.end());
    CHECK(std::adjacent_find(listed.begin(), listed.end()) == listed.end());
    CHECK(listed.size() == boxes.size());
    // Every leaf that lists a triangle lies under exactly one subtree.
    std::vector<std::uint32_t> covered;
    for (const BspSubtreeBox& b : boxes) leaves_under(plain.compact(), b.slot, covered);
    std::sort(covered.begin(), covered.end());
    CHECK(covered == [&] { auto v = all_leaves; std::sort(v.begin(), v.end()); return v; }());
  }
}

TEST_CASE("box top: shrunk boxes lose hits and the comparison sees it", "[bsp]") {
  const BspScene s = build_bsp_scene(load_mesh(scene_path("suzanne.obj")));
  BspTracer tracer(s.flat, s.soup);
  std::vector<BspSubtreeBox> boxes = tracer.subtree_boxes(64);
  for (BspSubtreeBox& b : boxes) {  // a tenth off each side: triangles near box faces fall out
    const Vec3f d = b.box.diagonal() * 0.1f;
    b.box.lo += d;
    b.box.hi -= d;
  }
  tracer.set_box_top(build_box_top(boxes));
  CHECK(tracer.name() == "bsp-top-float");
  const Comparison c = compare_with_brute(s.soup, tracer, all_ray_sets(s.soup, 300, 7));
  INFO("lost " << c.lost << ", farther " << c.farther << " of " << c.hits);
  CHECK(c.lost + c.farther > 0);
  CHECK_FALSE(c.ok());
}

TEST_CASE("bsp node widening: without max and min it equals the ordered one except below zero, where the far child starts at tmin",
          "[bsp]") {
  using detail::Order;
  std::mt19937 rng(7);
  std::vector<float> qs = {0.0f, -0.0f, 0x1p-149f, -0x1p-149f, 0x1p-127f, -0x1p-127f, 0x1p-126f, -0x1p-126f, 1.0f, -1.0f,
                           std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
                           std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                           std::numeric_limits<float>::quiet_NaN()};
  for (int i = 0; i < 20000; ++i) qs.push_back(std::bit_cast<float>(std::uint32_t(rng())));  // every exponent
  const auto same = [](float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b) ||
                                                  (std::isnan(a) && std::isnan(b)); };
  std::size_t negative = 0;
  for (const float q : qs) {
    const float up_o = detail::widen_up_as<Order::Ordered>(q, false), dn_o = detail::widen_dn_as<Order::Ordered>(q, false);
    const float up_n = detail::widen_up_as<Order::NonNegative>(q, true),
                dn_n = detail::widen_dn_as<Order::NonNegative>(q, true);
    INFO("q = " << q);
    // PerLane: the lane's own choice, bit for bit.
    CHECK(same(detail::widen_up_as<Order::PerLane>(q, true), up_n));
    CHECK(same(detail::widen_dn_as<Order::PerLane>(q, true), dn_n));
    CHECK(same(detail::widen_up_as<Order::PerLane>(q, false), up_o));
    CHECK(same(detail::widen_dn_as<Order::PerLane>(q, false), dn_o));
    if (std::isnan(q) || std::isinf(q) || !std::signbit(q) || q == 0.0f) {
      CHECK(same(up_n, up_o));
      CHECK(same(dn_n, dn_o));
    } else {
      // q < 0 and tmin >= 0: the far child is entered from tmin (max(dn, tmin)),
      // with either widening.
      ++negative;
      CHECK(dn_n < 0.0f);
      CHECK(dn_o < 0.0f);
    }
  }
  CHECK(negative > 5000);
}

TEST_CASE("BSP packets equal single rays exactly", "[bsp]") {
  const BspScene s = build_bsp_scene(load_mesh(scene_path("suzanne.obj")));
  const BspScene q = build_bsp_scene(make_default_scene());
  for (const BspScene* sc : {&s, &q}) {
    BspTracer tracer(sc->flat, sc->soup);
    tracer.set_packets(BspPackets::Always);  // the packet kernel on incoherent packets too
    std::vector<Ray> rays = all_ray_sets(sc->soup, 1000, 11);
    // The same rays again, every third from a point inside the scene's box with
    // tnear < 0 (its interval starts behind the origin, negative crossings): packets
    // that mix such lanes with ordinary ones.
    const Box3f box = sc->soup.bounds();
    const Vec3f mid = (box.lo + box.hi) * 0.5f;
    const std::size_t n = rays.size();
    for (std::size_t i = 0; i < n; ++i) {
      Ray r = rays[i];
      if (i % 3 == 0) {
        r.org = mid + (r.org - mid) * 0.01f;
        r.tnear = -1e6f;
      }
      rays.push_back(r);
    }
    std::vector<Hit> single(rays.size());
    RayCounters cs;
    tracer.trace_batch(rays, single, 1, &cs);
    for (int w : {4, 8, 16}) {
      if (int(detected_isa()) < int(isa_for_width(w))) continue;
      std::vector<Hit> packed(rays.size());
      RayCounters cp;
      tracer.trace_batch(rays, packed, w, &cp);
      std::size_t diff = 0;
      for (std::size_t i = 0; i < rays.size(); ++i)
        diff += std::memcmp(&single[i], &packed[i], sizeof(Hit)) != 0;
      INFO("width " << w);
      CHECK(diff == 0);
      CHECK(cp.rays == cs.rays);
      CHECK(cp.bsp_node_visits == cs.bsp_node_visits);
      CHECK(cp.kd_node_visits == cs.kd_node_visits);
      CHECK(cp.leaf_visits == cs.leaf_visits);
      CHECK(cp.triangle_tests == cs.triangle_tests);
      std::vector<Hit> nocount(rays.size());
      tracer.trace_batch(rays, nocount, w, nullptr);
      CHECK(std::memcmp(nocount.data(), packed.data(), rays.size() * sizeof(Hit)) == 0);
    }
  }
}

TEST_CASE("packet_looks_coherent: a camera tile is, random directions are not, invalid lanes do not count",
          "[bsp]") {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  std::vector<Ray> tile;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) tile.push_back({{0, 0, 0}, 0, {-0.05f + 0.01f * x, 1, 0.03f - 0.01f * y}});
  CHECK(packet_looks_coherent(tile));
  // Straddling an axis (mixed direction signs) is still one narrow cone.
  CHECK(packet_looks_coherent(std::vector<Ray>{{{0, 0, 0}, 0, {-0.01f, 1, 0}}, {{0, 0, 0}, 0, {0.01f, 1, 0}}}));
  std::vector<Ray> wide = tile;
  wide[7].dir = {1, 1, 0};  // 45 degrees from the others
  CHECK_FALSE(packet_looks_coherent(wide));
  wide[7].dir = {0.05f, -1, 0};  // opposite
  CHECK_FALSE(packet_looks_coherent(wide));
  std::vector<Ray> invalid = tile;
  invalid[0].dir = {0, 0, 0}, invalid[3].dir = {nan, 1, 0}, invalid[5].dir = {inf, 1, 0};
  CHECK(packet_looks_coherent(invalid));
  CHECK(packet_looks_coherent(std::span<const Ray>(tile.data(), 1)));
  CHECK(packet_looks_coherent(std::span<const Ray>()));
  // Huge and tiny direction lengths: no overflow to a false "not coherent".
  std::vector<Ray> scaled = tile;
  for (Ray& r : scaled) r.dir = r.dir * 0x1p60f;
  CHECK(packet_looks_coherent(scaled));
  // The batch test shares the angle test: it overflowed in float there and
  // called such a batch incoherent (a kernel choice only; hits were the same).
  CHECK(rays_look_coherent(scaled));
  CHECK_FALSE(rays_look_coherent(std::vector<Ray>{{{0, 0, 0}, 0, {0x1p60f, 0, 0}}, {{0, 0, 0}, 0, {0, 0x1p60f, 0}}}));
}

// Packets of incoherent rays (random, vertex, path-traced) ran 25-35 % slower
// through the BSP packet kernel than as single rays (docs/perf/bench.csv at
// 93d582f); they now run as single rays. Every way gives the same hits.
TEST_CASE("bsp packets: batches mixing coherent and incoherent packets equal single rays and the kernel",
          "[bsp][exact]") {
  const TriangleSoup soup = load_mesh(scene_path("suzanne.obj"));
  const std::vector<Ray> camera = make_rays(RaySetKind::Primary, soup, 700, 3);
  const std::vector<Ray> random = make_rays(RaySetKind::Random, soup, 700, 4);
  // Runs of coherent and incoherent packets of every length, batch sizes not a multiple of 16.
  std::vector<Ray> rays;
  for (std::size_t i = 0, c = 0, r = 0, k = 1; c + 64 < camera.size() && r + 64 < random.size(); ++i, ++k) {
    const std::size_t take = 5 * k % 61 + 3;
    const std::vector<Ray>& from = i % 2 ? random : camera;
    std::size_t& at = i % 2 ? r : c;
    rays.insert(rays.end(), from.begin() + long(at), from.begin() + long(at + take));
    at += take;
  }
  for (const char* accel : {"bsp", "bsp-float"}) {
    AccelOptions always;
    always.bsp_packets = BspPackets::Always;
    const std::unique_ptr<Accelerator> a = make_tracer(accel, soup), k = make_tracer(accel, soup, always);
    std::vector<Hit> single(rays.size());
    a->trace_batch(rays, single, 1);
    for (int w : {4, 8, 16}) {
      if (int(detected_isa()) < int(isa_for_width(w))) continue;
      for (std::size_t batch : {rays.size(), std::size_t(37), std::size_t(5)}) {
        std::vector<Hit> got(rays.size()), kernel(rays.size());
        for (std::size_t b = 0; b < rays.size(); b += batch) {
          const std::size_t m = std::min(batch, rays.size() - b);
          a->trace_batch(std::span<const Ray>(rays.data() + b, m), std::span<Hit>(got.data() + b, m), w);
          k->trace_batch(std::span<const Ray>(rays.data() + b, m), std::span<Hit>(kernel.data() + b, m), w);
        }
        INFO(accel << ", packets of " << w << ", batches of " << batch);
        CHECK(std::memcmp(got.data(), single.data(), rays.size() * sizeof(Hit)) == 0);
        CHECK(std::memcmp(kernel.data(), single.data(), rays.size() * sizeof(Hit)) == 0);
      }
    }
    CHECK(std::count_if(single.begin(), single.end(), [](const Hit& h) { return h.hit(); }) > 100);
  }
}

TEST_CASE("exact packets: bsp and kd equal their single rays and the exact reference at every width",
          "[bsp][kd][exact]") {
  // Exact leaves in packets test each triangle against all lanes in the
  // packet prefilter (traverse/simd/exact_packet_filter.h) and run the scalar
  // exact test for the lanes it keeps. Rays through vertices and edges (exact
  // zeros, rules, ties) and coplanar stacks are where a wrong bound would drop
  // a lane that hits. Sorted by direction octant, so the kd-tree's packets are
  // coherent and not traced as single rays.
  std::vector<std::pair<std::string, TriangleSoup>> scenes;
  scenes.emplace_back("suzanne", load_mesh(scene_path("suzanne.obj")));
  scenes.emplace_back("default scene", make_default_scene());
  scenes.emplace_back("coplanar stack", make_coplanar_stack());
  scenes.emplace_back("slivers", make_slivers());
  for (const auto& [name, soup] : scenes) {
    std::vector<Ray> rays = all_ray_sets(soup, 400, 21);
    const auto octant = [](const Ray& r) {
      return int(std::signbit(r.dir.x)) | int(std::signbit(r.dir.y)) << 1 | int(std::signbit(r.dir.z)) << 2;
    };
    std::stable_sort(rays.begin(), rays.end(), [&](const Ray& a, const Ray& b) { return octant(a) < octant(b); });
    std::vector<Hit> ref(rays.size());
    make_tracer("exact", soup)->trace_batch(rays, ref, 1);
    std::size_t hits = 0;
    for (const Hit& h : ref) hits += h.hit();
    for (const char* accel : {"bsp", "kd"}) {
      AccelOptions always;
      always.bsp_packets = BspPackets::Always;  // the packet kernel on incoherent packets too
      const std::unique_ptr<Accelerator> t = make_tracer(accel, soup, always);
      std::vector<Hit> single(rays.size());
      t->trace_batch(rays, single, 1);
      std::size_t wrong = 0;
      for (std::size_t i = 0; i < rays.size(); ++i)
        wrong += single[i].prim != ref[i].prim || (ref[i].hit() && single[i].t != ref[i].t);
      INFO(name << ", " << accel);
      CHECK(wrong == 0);
      for (int w : {4, 8, 16}) {
        if (int(detected_isa()) < int(isa_for_width(w))) continue;
        std::vector<Hit> packed(rays.size());
        t->trace_batch(rays, packed, w);
        std::size_t diff = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) diff += std::memcmp(&single[i], &packed[i], sizeof(Hit)) != 0;
        INFO("width " << w);
        CHECK(diff == 0);
      }
    }
    CHECK(hits > rays.size() / 4);
  }
}

// Found by the test above when it was written: the kd-tree's reciprocal 1/d
// overflowed to inf for a subnormal direction component, which put every
// crossing of that axis, the root box's included, at ±inf; a ray that reaches
// the triangle at t = 2^119 missed it (kd and kd-float, single rays and
// packets). Now such a reciprocal is NaN, which culls nothing, as in the BSP.
// The rays are those of "bvh8: a subnormal shear ..." (test_bvh8.cpp), in
// packets too, where a lane whose shear is subnormal keeps every triangle.
TEST_CASE("kd and exact packets: a subnormal direction component loses no hit", "[bsp][kd][exact][regression]") {
  const auto one_triangle = [](Vec3f a, Vec3f b, Vec3f c) {
    TriangleSoup s;
    s.vertices = {a, b, c};
    s.triangles = {{0, 1, 2}};
    classify_degenerate(s);
    return s;
  };
  const float z = 0x1p120f, w = 1.0f + 9 * 0x1p-13f;
  const std::pair<TriangleSoup, Vec3f> cases[] = {
      {one_triangle({0x1p-30f, -1, z}, {0x1p-30f, 1, z}, {0x1.ap-30f, 0, z}), {0x1p-149f, 0, 1.5f}},
      {one_triangle({-600 * 0x1p-149f, 0, 1}, {513 * 0x1p-149f, 0x1p40f, w}, {512 * 0x1p-149f, -0x1p41f, w}),
       {0x1p-140f, 0, 1}}};
  std::vector<std::pair<TriangleSoup, Vec3f>> all(std::begin(cases), std::end(cases));
  {  // case 1 with a second triangle beside the ray, so that splits on x separate the two
    TriangleSoup s = cases[0].first;
    s.vertices.insert(s.vertices.end(), {{-2, -1, 0}, {-1, -1, 0}, {-1.5f, 1, 1}});
    s.triangles.push_back({3, 4, 5});
    classify_degenerate(s);
    all.emplace_back(s, cases[0].second);
  }
  for (const auto& [soup, dir] : all) {
    std::vector<Ray> rays(16);
    for (Ray& r : rays) r.org = {0, 0, 0}, r.dir = dir;
    const Hit want = make_tracer("exact", soup)->trace(rays[0]);
    REQUIRE(want.hit());
    for (const char* accel : {"bsp", "kd"}) {
      const std::unique_ptr<Accelerator> t = make_tracer(accel, soup);
      for (int w : {1, 4, 8, 16}) {
        if (w > 1 && int(detected_isa()) < int(isa_for_width(w))) continue;
        std::vector<Hit> got(rays.size());
        t->trace_batch(rays, got, w);
        INFO(accel << ", " << soup.size() << " triangles, width " << w << ", direction x " << dir.x << ", got t " << got[0].t << " prim " << got[0].prim
                   << ", exact t " << want.t);
        for (const Hit& h : got) CHECK((h.prim == want.prim && h.t == want.t));
      }
    }
  }
}

TEST_CASE("BSP interleaved single rays equal sequential ones exactly", "[bsp]") {
  const TriangleSoup suzanne = load_mesh(scene_path("suzanne.obj"));
  std::vector<std::pair<std::string, TriangleSoup>> scenes;
  scenes.emplace_back("suzanne", suzanne);
  scenes.emplace_back("suzanne + 1e5", transformed(suzanne, 1.0f, {1e5f, -1e5f, 1e5f}));
  scenes.emplace_back("suzanne * 1e-4", transformed(suzanne, 1e-4f, {0, 0, 0}));
  scenes.emplace_back("coplanar stack", make_coplanar_stack());
  scenes.emplace_back("slivers", make_slivers());
  scenes.emplace_back("default scene", make_default_scene());
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (const auto& [name, soup] : scenes) {
    const BspScene s = build_bsp_scene(soup);
    std::vector<Ray> rays = all_ray_sets(s.soup, 500, 13);
    // Rays from inside the box with tnear < 0, and invalid rays, between ordinary ones.
    const Box3f box = s.soup.bounds();
    const Vec3f mid = (box.lo + box.hi) * 0.5f;
    const std::size_t n = rays.size();
    for (std::size_t i = 0; i < n; i += 3) rays.push_back({mid + (rays[i].org - mid) * 0.01f, -1e6f, rays[i].dir});
    for (std::size_t i = 0; i < n; i += 50) {
      rays.push_back({rays[i].org, 0, {nan, 1, 0}});
      rays.push_back({rays[i].org, 0, {0, 0, 0}});
      rays.push_back({{inf, 0, 0}, 0, rays[i].dir});
    }
    std::mt19937 rng(3);
    std::shuffle(rays.begin(), rays.end(), rng);
    for (BspEpsilon eps : {BspEpsilon::Certified, BspEpsilon::Zero}) {
      BspTracer tracer(s.flat, s.soup, eps);
      std::vector<Hit> one(rays.size());
      for (std::size_t i = 0; i < rays.size(); ++i) one[i] = tracer.trace(rays[i]);
      // Whole batch, and batches of fewer rays than lanes (3, 1, 0).
      for (std::size_t batch : {rays.size(), std::size_t(3), std::size_t(1)}) {
        for (BspSingleRays how : {BspSingleRays::Interleaved, BspSingleRays::Sequential, BspSingleRays::Auto}) {
          tracer.set_single_rays(how);
          std::vector<Hit> got(rays.size());
          for (std::size_t b = 0; b < rays.size(); b += batch) {
            const std::size_t m = std::min(batch, rays.size() - b);
            tracer.trace_batch(std::span<const Ray>(rays.data() + b, m), std::span<Hit>(got.data() + b, m), 1);
          }
          std::size_t diff = 0;
          for (std::size_t i = 0; i < rays.size(); ++i) diff += std::memcmp(&one[i], &got[i], sizeof(Hit)) != 0;
          INFO(name << ", zero eps " << (eps == BspEpsilon::Zero) << ", batch " << batch << ", mode " << int(how));
          CHECK(diff == 0);
        }
      }
      tracer.set_single_rays(BspSingleRays::Interleaved);
      std::vector<Hit> none;
      tracer.trace_batch(std::span<const Ray>(), none, 1);
      CHECK(std::count_if(one.begin(), one.end(), [](const Hit& h) { return h.hit(); }) > 0);
    }
  }
}

TEST_CASE("camera rays look coherent and random rays do not and shadow segments are bounded", "[bsp]") {
  const TriangleSoup soup = load_mesh(scene_path("suzanne.obj"));
  for (RaySetKind k : {RaySetKind::Random, RaySetKind::Vertex, RaySetKind::Edge})
    CHECK_FALSE(rays_look_coherent(make_rays(k, soup, 4096, 5)));
  const std::vector<Ray> primary = make_rays(RaySetKind::Primary, soup, 4096, 5);
  CHECK(rays_look_coherent(primary));
  CHECK(rays_look_coherent(std::span<const Ray>(primary.data(), 2)));
  CHECK(rays_look_coherent(std::span<const Ray>()));
  // Generated rays are unbounded; segments (tfar finite, like shadow rays) are not.
  for (RaySetKind k : {RaySetKind::Random, RaySetKind::Primary}) {
    std::vector<Ray> rays = make_rays(k, soup, 4096, 5);
    CHECK(rays_unbounded(rays));
    for (Ray& r : rays) r.tfar = 1.0f;
    CHECK_FALSE(rays_unbounded(rays));
  }
  CHECK_FALSE(rays_unbounded(std::span<const Ray>()));
}

TEST_CASE("automatic single rays: small trees run sequentially, larger ones interleaved", "[bsp]") {
  // Incoherent unbounded rays interleave only when the tree outgrows the L1
  // data cache (kInterleaveMinBytes): on the cube's 1.5 KB tree vertex-aimed
  // rays ran 1.6x slower interleaved (docs/certified-epsilons.md §11).
  const BspScene cube = build_bsp_scene(load_mesh(scene_path("cube.obj")));
  const BspScene suzanne = build_bsp_scene(load_mesh(scene_path("suzanne.obj")));
  BspTracer small(cube.flat, cube.soup), large(suzanne.flat, suzanne.soup);
  REQUIRE(small.walk_bytes() < kInterleaveMinBytes);
  REQUIRE(large.walk_bytes() >= kInterleaveMinBytes);
  CHECK(small.walk_bytes() <= small.memory_bytes());
  for (RaySetKind k : {RaySetKind::Random, RaySetKind::Vertex, RaySetKind::Edge}) {
    const std::vector<Ray> rays = make_rays(k, suzanne.soup, 4096, 5);
    const std::vector<Ray> cube_rays = make_rays(k, cube.soup, 4096, 5);
    CHECK(large.interleaves(rays));
    CHECK_FALSE(large.interleaves(rays, true));  // counted: sequential
    CHECK_FALSE(small.interleaves(cube_rays));
    small.set_single_rays(BspSingleRays::Interleaved);
    CHECK(small.interleaves(cube_rays));  // forced, whatever the size
    small.set_single_rays(BspSingleRays::Auto);
    large.set_single_rays(BspSingleRays::Sequential);
    CHECK_FALSE(large.interleaves(rays));
    large.set_single_rays(BspSingleRays::Auto);
  }
  CHECK_FALSE(large.interleaves(make_rays(RaySetKind::Primary, suzanne.soup, 4096, 5)));  // coherent
  // Same hits either way (the kernels' equality is tested above at every batch size).
  const std::vector<Ray> rays = make_rays(RaySetKind::Vertex, cube.soup, 2000, 9);
  std::vector<Hit> automatic(rays.size()), interleaved(rays.size());
  small.trace_batch(rays, automatic, 1);
  small.set_single_rays(BspSingleRays::Interleaved);
  small.trace_batch(rays, interleaved, 1);
  CHECK(std::memcmp(automatic.data(), interleaved.data(), rays.size() * sizeof(Hit)) == 0);
}

TEST_CASE("BSP rays from inside closed meshes never escape", "[bsp]") {
  for (const auto& [scale, shift] : {std::pair{1.0f, Vec3f{0, 0, 0}}, std::pair{1e-4f, Vec3f{0, 0, 0}},
                                     std::pair{1.0f, Vec3f{1e4f, -1e4f, 0}}}) {
    const BspScene s = build_bsp_scene(transformed(make_icosphere({0, 0, 0}, 1.0f, 3), scale, shift));
    for (std::uint32_t top : {0u, 1u, 64u}) {
      const BspTracer tracer = make_bsp(s.flat, s.soup, top);
      std::mt19937 rng(5);
      std::uniform_real_distribution<float> u(-1.0f, 1.0f);
      std::size_t escaped = 0;
      for (int i = 0; i < 4000; ++i) {
        Vec3f p{u(rng), u(rng), u(rng)}, d{u(rng), u(rng), u(rng)};
        if (length(p) > 0.9f || length(d) < 1e-3f) continue;
        if (i % 4 == 0) d = {0, 0, d.z < 0 ? -1.0f : 1.0f};          // axis-aligned
        if (i % 4 == 1) d = {d.x, 0, d.z};                            // a zero component
        escaped += !tracer.trace(Ray{p * scale + shift, 0, d}).hit();
      }
      INFO("scale " << scale << ", box top slots " << top);
      CHECK(escaped == 0);
    }
  }
}

namespace {
/// Rays the generators do not make: axis-aligned through vertices and along
/// faces, lying in triangle planes, subnormal and zero direction components,
/// origins inside cells, tnear > 0, negative tnear, finite tfar, huge origins
/// (the fallback mode).
std::vector<Ray> special_rays(const TriangleSoup& soup) {
  std::vector<Ray> rays;
  const Box3f b = soup.bounds();
  const Vec3f c = b.center(), e = b.diagonal();
  for (std::uint32_t t = 0; t < soup.size(); t += std::max<std::uint32_t>(1, std::uint32_t(soup.size() / 60))) {
    const Vec3f p0 = soup.corner(t, 0), p1 = soup.corner(t, 1), p2 = soup.corner(t, 2);
    for (int k = 0; k < 3; ++k) {  // axis-aligned through a corner, from outside
      Vec3f o = p0, d{0, 0, 0};
      o[k] = b.lo[k] - e[k];
      d[k] = 1.0f;
      rays.push_back({o, 0, d});
    }
    rays.push_back({p0, 0, p1 - p0});                        // along an edge (in its planes)
    rays.push_back({p0 - (p2 - p0), 0, p2 - p0});            // along an edge line, from outside
    rays.push_back({(p0 + p1) * 0.5f, 0, p2 - (p0 + p1) * 0.5f});  // in the face plane
    rays.push_back({c, 0, p0 - c});                          // from the centre to a corner
    rays.push_back({c, 0.5f, p1 - c});                       // tnear > 0
    rays.push_back({c - (p2 - c), -1.0f, p2 - c});           // negative tnear
    rays.push_back({c, 0, (p0 + p1 + p2) * (1.0f / 3.0f) - c});
    rays.back().tfar = 0.999f;                               // stops just short
    rays.push_back({c, 0, {1e-40f, -3e-39f, p0.z - c.z == 0 ? 1.0f : p0.z - c.z}});  // subnormal
    rays.push_back({Vec3f{1e30f, 0, 0} + c, 0, {-1e30f, 1e22f, 0}});  // huge: fallback mode
  }
  return rays;
}
}  // namespace

TEST_CASE("BSP special rays equal brute force", "[bsp]") {
  for (const char* name : {"cube.obj", "suzanne.obj", "stiff_cube_with_fold.ply", "stiff_planexy.off"}) {
    const BspScene s = build_bsp_scene(load_mesh(scene_path(name)));
    const std::vector<Ray> rays = special_rays(s.soup);
    for (std::uint32_t top : {0u, 1u, 64u}) {
      const Comparison c = compare_with_brute(s.soup, make_bsp(s.flat, s.soup, top), rays);
      INFO(name << " (box top slots " << top << "): " << c.rays << " rays, lost " << c.lost << ", farther "
                << c.farther << ", impossible " << c.impossible << "; first: " << c.first_failure);
      CHECK(c.ok());
    }
  }
  const BspScene g = build_bsp_scene(make_default_scene());
  for (std::uint32_t top : {0u, 1u, 64u}) {
    const Comparison c = compare_with_brute(g.soup, make_bsp(g.flat, g.soup, top), special_rays(g.soup));
    INFO("default scene (box top slots " << top << "): first: " << c.first_failure);
    CHECK(c.ok());
  }
}

// Found measuring the huge-ray fallback (docs/notes/2026-12-01-direction-scaling.md,
// 2026-12-01): a ray whose direction was multiplied by 2^70 or 2^-70, the same
// geometric ray, visited every node and leaf of the tree: 12 ms a ray on the
// bunny, 7x brute force. The traversal now follows the direction scaled back
// into range by a power of two (bsp_kernel.h scale_direction) and bounds its
// hits in the scaled parameter (hit_bound); the leaf test keeps the ray as given.
TEST_CASE("BSP: a direction scaled out of range by a power of two is traced at normal cost", "[bsp][regression]") {
  const TriangleSoup soup = load_mesh(scene_path("suzanne.obj"));
  const BspScene s = build_bsp_scene(soup);
  std::vector<Ray> base = all_ray_sets(s.soup, 150, 17);
  for (std::size_t i = 0; i < base.size(); i += 4) base[i].tfar = 2.5f;  // bounded segments too
  BspTracer plain(s.flat, s.soup);
  plain.set_packets(BspPackets::Always);  // the packet kernel on incoherent packets too
  RayCounters cb;
  std::vector<Hit> hb(base.size());
  plain.trace_batch(base, hb, 1, &cb);
  const std::uint64_t base_visits = cb.kd_node_visits + cb.bsp_node_visits;
  REQUIRE(base_visits > 0);
  const std::unique_ptr<Accelerator> exact = make_tracer("exact", soup);
  const std::unique_ptr<Accelerator> certified = make_tracer("bsp", soup);
  for (const float scale : {0x1p70f, 0x1p-70f, 0x1p100f, 0x1p-100f, 0x1p65f, 0x1p-65f}) {
    std::vector<Ray> rays = base;
    for (Ray& r : rays) {
      r.dir = r.dir * scale;
      r.tnear /= scale;
      r.tfar /= scale;
    }
    INFO("direction scaled by " << scale);
    // Hits: brute force up to ties, plainly and under a box top.
    for (std::uint32_t top : {0u, 64u}) {
      const Comparison c = compare_with_brute(s.soup, make_bsp(s.flat, s.soup, top), rays);
      INFO("box top slots " << top << ": " << c.hits << " hits, lost " << c.lost << ", farther " << c.farther
                            << ", impossible " << c.impossible << "; first: " << c.first_failure);
      CHECK(c.ok());
      CHECK(c.hits > 0);
    }
    // The work of ordinary rays, not of the fallback (tens of thousands of
    // node visits a ray on suzanne).
    RayCounters cs;
    std::vector<Hit> single(rays.size());
    plain.trace_batch(rays, single, 1, &cs);
    CHECK(cs.kd_node_visits + cs.bsp_node_visits <= 2 * base_visits);
    CHECK(cs.leaf_visits <= 2 * cb.leaf_visits);
    // Packets and interleaved single rays make the same steps: packets of
    // scaled lanes only, and packets mixing scaled and ordinary lanes.
    std::vector<Ray> mixed;
    for (std::size_t i = 0; i < rays.size(); ++i) mixed.push_back(i % 3 == 0 ? base[i] : rays[i]);
    for (const std::vector<Ray>* set : {&rays, &mixed}) {
      RayCounters c1;
      std::vector<Hit> one(set->size());
      plain.trace_batch(*set, one, 1, &c1);
      for (int w : {4, 8, 16}) {
        if (int(detected_isa()) < int(isa_for_width(w))) continue;
        RayCounters cp;
        std::vector<Hit> packed(set->size());
        plain.trace_batch(*set, packed, w, &cp);
        INFO("packets of " << w << (set == &mixed ? ", mixed lanes" : ""));
        CHECK(std::memcmp(packed.data(), one.data(), set->size() * sizeof(Hit)) == 0);
        CHECK(cp.kd_node_visits == c1.kd_node_visits);
        CHECK(cp.bsp_node_visits == c1.bsp_node_visits);
        CHECK(cp.leaf_visits == c1.leaf_visits);
      }
    }
    BspTracer interleaved(s.flat, s.soup);
    interleaved.set_single_rays(BspSingleRays::Interleaved);
    std::vector<Hit> inter(rays.size());
    interleaved.trace_batch(rays, inter, 1);
    CHECK(std::memcmp(inter.data(), single.data(), rays.size() * sizeof(Hit)) == 0);
    // The certified leaf test still equals the exact reference.
    std::vector<Hit> he(rays.size()), hc(rays.size());
    exact->trace_batch(rays, he, 1);
    certified->trace_batch(rays, hc, 1);
    const HitComparison x = compare_hits(he, hc);
    INFO("bsp (exact leaves) vs exact: lost " << x.lost << ", extra " << x.extra << ", farther " << x.farther
                                         << ", nearer " << x.nearer);
    CHECK(x.agrees());
  }
  // A direction whose scaled copy would round (a component goes subnormal) is
  // not scaled: it keeps the slow fallback and its hits.
  std::vector<Ray> odd;
  for (std::size_t i = 0; i < base.size(); i += 10) {
    Ray r = base[i];
    r.dir = {r.dir.x * 0x1p100f, 0x1p-40f * 1.00000012f, r.dir.z * 0x1p100f};
    odd.push_back(r);
  }
  const Comparison c = compare_with_brute(s.soup, plain, odd);
  INFO("unscalable directions: first: " << c.first_failure);
  CHECK(c.ok());
}

TEST_CASE("bsp: floors and walls on their cells' boundaries are kept in thin slabs (regression: "
          "stiff_two-boxes random rays, 4.76 triangle tests a ray against the kd-tree's 1.39)",
          "[bsp]") {
  // A closed room 10 x 4 x 10, each wall a grid of quads. After the split through
  // a wall's own plane the wall lies on its cell's boundary, where no kd candidate
  // at a triangle's bounds lies strictly inside the cell on that axis: without the
  // slab candidates (BspConfig::planar_slabs) every random ray that crosses such a
  // cell tests the wall's triangles in it, however far from the wall it passes.
  TriangleSoup room;
  const int q = 6;
  const auto quad = [&](Vec3f o, Vec3f u, Vec3f v) {
    for (int i = 0; i < q; ++i)
      for (int j = 0; j < q; ++j) {
        const Vec3f a = o + u * (float(i) / q) + v * (float(j) / q), b = a + u * (1.0f / q), c = a + v * (1.0f / q);
        const Vec3f d = b + v * (1.0f / q);
        const std::uint32_t k = std::uint32_t(room.vertices.size());
        room.vertices.insert(room.vertices.end(), {a, b, d, c});
        room.triangles.push_back({k, k + 1, k + 2});
        room.triangles.push_back({k, k + 2, k + 3});
      }
  };
  const Vec3f x{10, 0, 0}, y{0, 4, 0}, z{0, 0, 10};
  quad({0, 0, 0}, x, z);  // floor
  quad(y, z, x);          // ceiling
  quad({0, 0, 0}, z, y);  // the four walls
  quad(x, y, z);
  quad({0, 0, 0}, y, x);
  quad(z, x, y);
  BspConfig with, without;
  with.threads = without.threads = 1;
  without.planar_slabs = false;
  REQUIRE(with.planar_slabs);  // the default
  const BspScene a = build_bsp_scene(room, with), b = build_bsp_scene(room, without);
  REQUIRE_NOTHROW(a.exact.validate(a.soup.size(), &a.soup));
  REQUIRE_NOTHROW(a.flat.validate());
  const BspTracer slabs(a.flat, a.soup), none(b.flat, b.soup);
  const std::vector<Ray> rays = make_rays(RaySetKind::Random, a.soup, 20000, 7);
  std::vector<Hit> ha(rays.size()), hb(rays.size());
  RayCounters ca, cb;
  slabs.trace_batch(rays, ha, 1, &ca);
  none.trace_batch(rays, hb, 1, &cb);
  const double n = double(rays.size());
  INFO("triangle tests a random ray: " << double(ca.triangle_tests) / n << " with slabs, "
                                        << double(cb.triangle_tests) / n << " without");
  CHECK(double(ca.triangle_tests) <= 0.5 * double(cb.triangle_tests));
  for (const BspTracer* t : {&slabs, &none}) {
    const Comparison c = compare_with_brute(a.soup, *t, rays);
    INFO((t == &slabs ? "with slabs" : "without") << ": lost " << c.lost << ", farther " << c.farther
                                                   << "; first: " << c.first_failure);
    CHECK(c.ok());
    CHECK(c.hits > rays.size() / 2);
  }
}

TEST_CASE("BSP flat sections round-trip through a tree file", "[bsp]") {
  const BspScene s = build_bsp_scene(load_mesh(scene_path("suzanne.obj")));
  const std::string path = temp_path("suzanne_flat.bsp");
  write_bsp_file_with_flat(path, s.soup, s.exact, s.flat);
  const TreeFileReader r(path);
  REQUIRE(has_flat_bsp_sections(r));
  const FlatBspTree back = read_flat_bsp_sections(r, s.soup);
  REQUIRE(back.nodes.size() == s.flat.nodes.size());
  CHECK(std::memcmp(back.nodes.data(), s.flat.nodes.data(), back.nodes.size() * sizeof(FlatBspNode)) == 0);
  CHECK(back.prims == s.flat.prims);
  TriangleSoup other = s.soup;
  other.triangles.pop_back();
  CHECK_THROWS_AS(read_flat_bsp_sections(r, other), InputError);
}

TEST_CASE("BSP work per ray: certified vs zero epsilon vs kd-tree", "[bsp][report]") {
  for (const char* name : {"suzanne.obj", "utah-teapot.obj"}) {
    const BspScene s = build_bsp_scene(load_mesh(scene_path(name)));
    const KdTracer kd(build_kd(s.soup), s.soup);
    const BspTracer cert(s.flat, s.soup), zero(s.flat, s.soup, BspEpsilon::Zero);
    for (RaySetKind k : {RaySetKind::Primary, RaySetKind::Random, RaySetKind::Vertex}) {
      const std::vector<Ray> rays = make_rays(k, s.soup, 4096, 3);
      RayCounters a, z, d;
      std::vector<Hit> h(rays.size()), hz(rays.size());
      cert.trace_batch(rays, h, 1, &a);
      zero.trace_batch(rays, hz, 1, &z);
      std::vector<Hit> hd(rays.size());
      kd.trace_batch(rays, hd, 1, &d);
      const auto per = [&](std::uint64_t x) { return double(x) / double(rays.size()); };
      fmt::print("{:16} {:8} certified: bsp {:6.2f} kd {:6.2f} leaves {:5.2f} tris {:5.2f} | zero-eps: "
                 "bsp {:6.2f} kd {:6.2f} tris {:5.2f} | kd-tree: nodes {:6.2f} tris {:5.2f}\n",
                 name, ray_set_name(k), per(a.bsp_node_visits), per(a.kd_node_visits),
                 per(a.leaf_visits), per(a.triangle_tests), per(z.bsp_node_visits),
                 per(z.kd_node_visits), per(z.triangle_tests), per(d.kd_node_visits),
                 per(d.triangle_tests));
      // Visit counts are not monotone in epsilon (an earlier hit can cull later
      // nodes), but hits are: the certified traversal finds every hit the float
      // triangle test can report, the zero-epsilon one at most as many.
      const auto hits = [](const std::vector<Hit>& v) { return std::count_if(v.begin(), v.end(), [](const Hit& x) { return x.hit(); }); };
      CHECK(hits(h) >= hits(hz));
      CHECK(hits(h) == hits(hd));  // the kd-tree is conservative too: same hit set
    }
  }
}

// Any-hit (Accelerator::occluded): the BSP and the kd-tree stop after the first
// leaf that yields a hit. The answer must be the exact reference's "hits in
// [tnear, tfar]" for the exact modes and trace().hit() for the float ones, on
// rays through vertices and edges, lines, short segments and shadow-like
// segments between two surface points; the early stop must save work.
TEST_CASE("bsp and kd: occluded equals the nearest hit's existence and stops early", "[bsp][kd]") {
  const TriangleSoup soup = load_mesh(scene_path("utah-teapot.obj"));
  std::vector<Ray> rays;
  for (RaySetKind k : {RaySetKind::Primary, RaySetKind::Random, RaySetKind::Vertex, RaySetKind::Edge}) {
    const std::vector<Ray> r = make_rays(k, soup, 400, 61 + std::uint64_t(k));
    rays.insert(rays.end(), r.begin(), r.end());
  }
  const std::size_t base = rays.size();
  for (std::size_t i = 0; i + 1 < base; i += 4) {
    Ray line = rays[i];
    line.tnear = -std::numeric_limits<float>::infinity();
    rays.push_back(line);
    Ray seg = rays[i + 1];
    seg.tfar = 0.5f;
    rays.push_back(seg);
  }
  std::mt19937 rng(5);
  std::uniform_int_distribution<std::size_t> pick(0, soup.triangles.size() - 1);
  for (int i = 0; i < 800; ++i) {  // from one surface point to another, t in [1e-4, 1]
    const auto a = soup.corners(pick(rng)), b = soup.corners(pick(rng));
    const Vec3f p = (a[0] + a[1] + a[2]) * (1.0f / 3.0f), q = (b[0] + b[1] + b[2]) * (1.0f / 3.0f);
    Ray r;
    r.org = p;
    r.dir = q - p;
    r.tnear = 1e-4f;
    r.tfar = 1.0f;
    rays.push_back(r);
  }
  const ExactTracer exact(soup);
  for (const char* mode : {"bsp", "bsp-float", "kd", "kd-float"}) {
    const auto t = make_tracer(mode, soup);
    const bool exact_mode = std::string(mode) == "bsp" || std::string(mode) == "kd";
    RayCounters nearest, any;
    std::size_t differ = 0, hits = 0;
    for (const Ray& r : rays) {
      const bool h = exact_mode ? exact.trace(r).hit() : t->trace(r, &nearest).hit();
      if (exact_mode) t->trace(r, &nearest);
      differ += h != t->occluded(r, &any) ? 1 : 0;
      hits += h ? 1 : 0;
    }
    INFO(mode << ": " << differ << " of " << rays.size() << " rays differ, " << hits << " hit");
    CHECK(differ == 0);
    CHECK(hits > rays.size() / 4);
    CHECK(hits < rays.size());
    CHECK(any.rays == nearest.rays);
    CHECK(any.leaf_visits <= nearest.leaf_visits);
    CHECK(any.triangle_tests < nearest.triangle_tests);
    CHECK(any.kd_node_visits + any.bsp_node_visits < nearest.kd_node_visits + nearest.bsp_node_visits);
  }
  // Embree's rtcOccluded1 (the path tracer's shadow rays use occluded in every
  // mode) against its own nearest hits; Embree takes no lines (tnear < 0).
  const auto embree = make_tracer("embree", soup);
  std::size_t differ = 0, checked = 0;
  for (const Ray& r : rays)
    if (r.tnear >= 0.0f) {
      differ += embree->trace(r).hit() != embree->occluded(r) ? 1 : 0;
      ++checked;
    }
  INFO("embree: " << differ << " of " << checked << " rays differ");
  CHECK(differ == 0);
  CHECK(checked > rays.size() / 2);
}

TEST_CASE("BSP comparison catches a tree whose planes were moved", "[bsp]") {
  // The oracle must be able to fail: move every split a little (plane offsets
  // and kd coordinates, epsilons zeroed) and lost hits must be reported.
  const BspScene s = build_bsp_scene(load_mesh(scene_path("suzanne.obj")));
  FlatBspTree bad = s.flat;
  for (std::size_t i = 0; i < bad.nodes.size(); ++i) {
    FlatBspNode& n = bad.nodes[i];
    if (n.is_plane()) {
      FlatBspNode& tail = bad.nodes[++i];
      tail.set_tail_d(tail.tail_d() + 2e-3f);
      tail.set_tail_eps(0.0f);
    } else if (n.is_kd() && n.split() > bad.bounds.lo[n.axis()] + 4e-3f) {
      n.set_split(n.split() - 2e-3f);
    }
  }
  const BspTracer tracer(bad, s.soup, BspEpsilon::Zero);
  const std::vector<Ray> rays = all_ray_sets(s.soup, 1000, 5);
  const Comparison c = compare_with_brute(s.soup, tracer, rays);
  CHECK(c.lost + c.farther > 0);
  CHECK_FALSE(c.ok());
}

TEST_CASE("BSP zero-epsilon variant: lost hits on stiff rays (report)", "[.report]") {
  for (const char* name : {"suzanne.obj", "utah-teapot.obj"}) {
    const BspScene s = build_bsp_scene(load_mesh(scene_path(name)));
    const BspTracer zero(s.flat, s.soup, BspEpsilon::Zero);
    const std::vector<Ray> rays = all_ray_sets(s.soup, 5000, 9);
    const Comparison c = compare_with_brute(s.soup, zero, rays);
    fmt::print("zero-eps {:16} rays {} lost {} farther {} ties {}\n", name, c.rays, c.lost,
               c.farther, c.ties);
  }
}

TEST_CASE("BSP vs kd speed on one mesh (manual: BSPRT_BENCH_MESH=file)", "[.bench]") {
  const char* mesh = std::getenv("BSPRT_BENCH_MESH");
  const std::string name = mesh ? mesh : "utah-teapot.obj";
  const auto now = [] { return std::chrono::steady_clock::now(); };
  const auto secs = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  TriangleSoup soup = load_mesh(scene_path(name));
  BspConfig cfg;
  if (const char* m = std::getenv("BSPRT_BSP_MAX_TRIS")) cfg.bsp_max_triangles = std::stoull(m);
  auto t0 = now();
  BspScene s = build_bsp_scene(std::move(soup), cfg);
  auto t1 = now();
  FlattenReport fr;
  s.flat = flatten_bsp(s.soup, s.exact, &fr);
  const KdTracer kd(build_kd(s.soup), s.soup);
  fmt::print("{}: build+flatten {:.2f}s (flatten {:.2f}s), plane nodes {}, kd nodes {} ({} from planes), "
             "max eps {:.3g}, mean eps {:.3g}, max eps/cell {:.3g}\n", name, secs(t0, t1), fr.seconds,
             fr.plane_nodes, fr.kd_nodes, fr.kd_from_planes, fr.max_eps, fr.mean_eps, fr.max_eps_rel_cell);
  const BspTracer bsp(s.flat, s.soup);
  for (RaySetKind k : {RaySetKind::Primary, RaySetKind::Random}) {
    const std::vector<Ray> rays = make_rays(k, s.soup, 1 << 18, 1);
    std::vector<Hit> h(rays.size());
    for (int w : {1, 4, 8, 16}) {
      if (int(detected_isa()) < int(isa_for_width(w))) continue;
      RayCounters cb, ck;
      auto a = now();
      bsp.trace_batch(rays, h, w, nullptr);
      auto b = now();
      kd.trace_batch(rays, h, w, nullptr);
      auto c = now();
      bsp.trace_batch(rays, h, w, &cb);
      kd.trace_batch(rays, h, w, &ck);
      const double n = double(rays.size());
      fmt::print("  {:8} w={:2}  bsp {:6.2f} Mrays/s  kd {:6.2f} Mrays/s  ratio {:.2f} | bsp nodes {:.1f}+{:.1f} tris {:.2f} | "
                 "kd nodes {:.1f} tris {:.2f}\n", ray_set_name(k), w, n / secs(a, b) * 1e-6,
                 n / secs(b, c) * 1e-6, secs(b, c) / secs(a, b), cb.kd_node_visits / n,
                 cb.bsp_node_visits / n, cb.triangle_tests / n, ck.kd_node_visits / n, ck.triangle_tests / n);
    }
  }
}
