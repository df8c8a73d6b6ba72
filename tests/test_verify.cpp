// bsprt verify (robust/verify.h): good trees certify, tampered tree files fail
// with the right counter-example, and the CLI reports both.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "builder/bsp/bsp_build.h"
#include "builder/bsp/bsp_file.h"
#include "builder/bsp/bsp_flat_io.h"
#include "builder/bsp/bsp_flatten.h"
#include "verify/verify_file.h"
#include "geometry/scenes/default_scene.h"
#include "geometry/io/load_mesh.h"
#include "robust/degenerate.h"
#include "verify/verify.h"
#include "test_util.h"

using namespace bsprt;
using bsprt::test::scene_path;
using bsprt::test::temp_path;

namespace {

const std::array<std::uint32_t, 7> kTags = {kBspHeaderTag, kBspPlanesTag, kBspNodesTag, kBspRefsTag,
                                            kFlatBspHeaderTag, kFlatBspNodesTag, kFlatBspPrimsTag};

/// A tree file's sections, editable, written back with a valid CRC.
struct Sections {
  std::map<std::uint32_t, std::vector<std::byte>> s;
  template <typename T>
  std::vector<T> get(std::uint32_t tag) const {
    std::vector<T> v(s.at(tag).size() / sizeof(T));
    std::memcpy(v.data(), s.at(tag).data(), v.size() * sizeof(T));
    return v;
  }
  template <typename T>
  void set(std::uint32_t tag, const std::vector<T>& v) {
    const auto b = std::as_bytes(std::span<const T>(v));
    s[tag].assign(b.begin(), b.end());
  }
};

Sections read_sections(const std::string& path) {
  const TreeFileReader r(path);
  Sections out;
  for (std::uint32_t tag : kTags) {
    const auto b = r.section(tag);
    out.s[tag].assign(b.begin(), b.end());
  }
  return out;
}

void write_sections(const std::string& path, const TriangleSoup& soup, const Sections& sec) {
  TreeFileWriter w(TreeKind::Bsp, soup);
  for (const auto& [tag, bytes] : sec.s) w.add_section(tag, bytes);
  w.write(path);
}

struct Built {
  TriangleSoup soup;
  std::string path;
};

Built build_file(TriangleSoup soup, const std::string& name, BspMembership m, bool coplanar_both = true) {
  classify_degenerate(soup);
  BspConfig cfg;
  cfg.membership = m;
  cfg.coplanar_to_both = coplanar_both;
  const BspTree exact = build_bsp(soup, cfg);
  Built b{std::move(soup), temp_path(name)};
  write_bsp_file_with_flat(b.path, b.soup, exact, flatten_bsp(b.soup, exact));
  return b;
}

VerifyReport verify_file(const Built& b) {
  return verify_bsp(b.soup, read_verify_input(b.path, b.soup));
}

VerifyReport verify_sections(const Built& b, const Sections& sec, const std::string& name) {
  const std::string p = temp_path(name);
  write_sections(p, b.soup, sec);
  return verify_bsp(b.soup, read_verify_input(p, b.soup));
}

void require_certified(const VerifyReport& r) {
  INFO((r.failure ? r.failure->describe() : std::string("ok")));
  REQUIRE(r.certified);
  CHECK(r.extra_listings == 0);
  CHECK(r.volume_rel_error < 1e-6);
  CHECK(r.pairs >= r.required_pairs);
}

/// Index of the first leaf (in BNOD order) with at least `min` triangles.
std::uint32_t leaf_with(const std::vector<VerifyNode>& nodes, std::uint32_t min, std::uint32_t skip = ~0u) {
  for (std::uint32_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].plane == VerifyNode::kLeaf && nodes[i].b >= min && i != skip) return i;
  FAIL("no leaf with enough triangles");
  return 0;
}

}  // namespace

TEST_CASE("verify certifies trees of the shared meshes in both membership rules", "[verify]") {
  for (const char* name : {"cube.obj", "suzanne.obj", "utah-teapot.obj", "stiff_degenerated.obj",
                           "stiff_planexy.off", "stiff_cube_with_fold.ply", "stiff_sliver_tet.ply",
                           "stiff_two-boxes-bad-self-union.ply"}) {
    for (BspMembership m : {BspMembership::Area, BspMembership::Closed}) {
      INFO(name << (m == BspMembership::Area ? " area" : " closed"));
      const Built b = build_file(load_mesh(scene_path(name)), "verify_mesh.tree", m);
      const VerifyReport r = verify_file(b);
      require_certified(r);
      CHECK(r.flat_plane_nodes + r.flat_kd_nodes + r.leaves == r.nodes);
    }
  }
}

TEST_CASE("verify certifies generated scenes, coplanar triangles on one side too", "[verify]") {
  TriangleSoup scene = make_icosphere({0, 0, 0}, 1.0f, 2);
  append(scene, make_ground({0, -1, 0}, 3.0f, 4));
  append(scene, make_torus_knot({2, 0, 0}, 0.8f, 0.2f, 2, 3, 64, 6));
  TriangleSoup far = make_icosphere({1e5f, 1e5f, 0}, 1.0f, 2);
  for (bool both : {true, false})
    for (BspMembership m : {BspMembership::Area, BspMembership::Closed}) {
      INFO("both " << both << " rule " << int(m));
      require_certified(verify_file(build_file(scene, "verify_gen.tree", m, both)));
      require_certified(verify_file(build_file(far, "verify_far.tree", m, both)));
    }
}

TEST_CASE("verify fails when a triangle is removed from a leaf", "[verify]") {
  for (BspMembership m : {BspMembership::Area, BspMembership::Closed}) {
    const Built b = build_file(load_mesh(scene_path("suzanne.obj")), "verify_rm.tree", m);
    Sections sec = read_sections(b.path);
    std::vector<VerifyNode> nodes = sec.get<VerifyNode>(kBspNodesTag);
    std::vector<std::uint32_t> refs = sec.get<std::uint32_t>(kBspRefsTag);
    const std::uint32_t leaf = leaf_with(nodes, 1);
    const std::uint32_t at = nodes[leaf].a, removed = refs[at];
    refs.erase(refs.begin() + at);
    --nodes[leaf].b;
    for (VerifyNode& n : nodes)
      if (n.plane == VerifyNode::kLeaf && n.a > at) --n.a;
    sec.set(kBspNodesTag, nodes);
    sec.set(kBspRefsTag, refs);
    const VerifyReport r = verify_sections(b, sec, "verify_rm_bad.tree");
    REQUIRE_FALSE(r.certified);
    INFO(r.failure->describe());
    CHECK(r.failure->node == leaf);
    CHECK(r.failure->triangle == removed);
    CHECK(r.failure->what.find("does not list") != std::string::npos);
    CHECK(r.failure->witness.has_value());
  }
}

TEST_CASE("verify fails when two leaf lists are swapped", "[verify]") {
  const Built b = build_file(load_mesh(scene_path("suzanne.obj")), "verify_sw.tree", BspMembership::Closed);
  Sections sec = read_sections(b.path);
  std::vector<VerifyNode> nodes = sec.get<VerifyNode>(kBspNodesTag);
  const std::vector<std::uint32_t> refs = sec.get<std::uint32_t>(kBspRefsTag);
  const std::uint32_t l1 = leaf_with(nodes, 1);
  std::uint32_t l2 = l1;
  for (std::uint32_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].plane == VerifyNode::kLeaf && nodes[i].b >= 1 && refs[nodes[i].a] != refs[nodes[l1].a]) {
      l2 = i;
      break;
    }
  REQUIRE(l2 != l1);
  std::swap(nodes[l1].a, nodes[l2].a);
  std::swap(nodes[l1].b, nodes[l2].b);
  sec.set(kBspNodesTag, nodes);
  const VerifyReport r = verify_sections(b, sec, "verify_sw_bad.tree");
  REQUIRE_FALSE(r.certified);
  INFO(r.failure->describe());
  CHECK((r.failure->node == l1 || r.failure->node == l2));
  CHECK(r.failure->triangle != 0xFFFFFFFFu);
}

TEST_CASE("verify fails when a kd plane is nudged by one ulp", "[verify]") {
  const Built b = build_file(load_mesh(scene_path("suzanne.obj")), "verify_kd.tree", BspMembership::Area);
  Sections sec = read_sections(b.path);
  std::vector<PlaneDef> planes = sec.get<PlaneDef>(kBspPlanesTag);
  const std::vector<VerifyNode> nodes = sec.get<VerifyNode>(kBspNodesTag);
  std::uint32_t node = 0;
  while (nodes[node].plane == VerifyNode::kLeaf || !planes[nodes[node].plane].is_kd()) ++node;
  PlaneDef& p = planes[nodes[node].plane];
  p = PlaneDef::kd(p.axis(), std::nextafter(p.coord(), INFINITY));
  sec.set(kBspPlanesTag, planes);
  const VerifyReport r = verify_sections(b, sec, "verify_kd_bad.tree");
  REQUIRE_FALSE(r.certified);
  INFO(r.failure->describe());
  CHECK(r.failure->node == node);
  CHECK(r.failure->what.find("flat kd node") != std::string::npos);
}

TEST_CASE("verify fails when a flat plane moves beyond its eps or its eps shrinks", "[verify]") {
  const Built b = build_file(load_mesh(scene_path("suzanne.obj")), "verify_eps.tree", BspMembership::Area);
  const Sections good = read_sections(b.path);
  const std::vector<FlatBspNode> flat = good.get<FlatBspNode>(kFlatBspNodesTag);
  std::uint32_t f = 0;
  while (!flat[f].is_plane()) ++f;
  for (int mode = 0; mode < 3; ++mode) {
    std::vector<FlatBspNode> bad = flat;
    const float d = bad[f + 1].tail_d(), eps = bad[f + 1].tail_eps();
    if (mode == 0) bad[f + 1].set_tail_d(d + 4 * eps);
    if (mode == 1) bad[f + 1].set_tail_d(d - 4 * eps);
    if (mode == 2) bad[f + 1].set_tail_eps(0.0f);
    Sections sec = good;
    sec.set(kFlatBspNodesTag, bad);
    const VerifyReport r = verify_sections(b, sec, "verify_eps_bad.tree");
    INFO("mode " << mode);
    REQUIRE_FALSE(r.certified);
    INFO(r.failure->describe());
    CHECK(r.failure->flat_node == f);
    CHECK(r.failure->what.find("eps does not cover") != std::string::npos);
    CHECK(r.failure->witness.has_value());
  }
}

TEST_CASE("verify fails on a flat leaf that differs and on a degenerate listed triangle", "[verify]") {
  TriangleSoup soup = load_mesh(scene_path("stiff_degenerated.obj"));
  classify_degenerate(soup);
  std::uint32_t degen = 0;
  while (degen < soup.size() && !soup.is_degenerate(degen)) ++degen;
  const Built b = build_file(soup, "verify_deg.tree", BspMembership::Closed);
  Sections sec = read_sections(b.path);
  std::vector<std::uint32_t> refs = sec.get<std::uint32_t>(kBspRefsTag);
  const std::vector<VerifyNode> nodes = sec.get<VerifyNode>(kBspNodesTag);
  const std::uint32_t leaf = leaf_with(nodes, 1);
  if (degen < soup.size()) {
    refs[nodes[leaf].a] = degen;
    Sections s2 = sec;
    s2.set(kBspRefsTag, refs);
    const VerifyReport r = verify_sections(b, s2, "verify_deg_bad.tree");
    REQUIRE_FALSE(r.certified);
    CHECK(r.failure->triangle == degen);
    CHECK(r.failure->what.find("degenerate") != std::string::npos);
  }
  std::vector<std::uint32_t> prims = sec.get<std::uint32_t>(kFlatBspPrimsTag);
  prims[0] = prims[0] + 1 < soup.size() ? prims[0] + 1 : 0;
  sec.set(kFlatBspPrimsTag, prims);
  const VerifyReport r = verify_sections(b, sec, "verify_flatleaf_bad.tree");
  REQUIRE_FALSE(r.certified);
  CHECK(r.failure->what.find("flat leaf") != std::string::npos);
}

using Run = bsprt::test::CliRun;
using bsprt::test::bsprt_cli;

TEST_CASE("bsprt verify: exit 0 and CERTIFIED, non-zero with the ids on a tampered tree", "[verify][cli]") {
  const std::string mesh = scene_path("suzanne.obj");
  const std::string tree = temp_path("verify_cli.tree");
  const Run build = bsprt_cli("build " + mesh + " --accel bsp -o " + tree);
  INFO(build.output);
  REQUIRE(build.status == 0);
  const Run ok = bsprt_cli("verify " + mesh + " " + tree);
  INFO(ok.output);
  CHECK(ok.status == 0);
  CHECK(ok.output.find("CERTIFIED") != std::string::npos);

  TriangleSoup soup = load_mesh(mesh);
  Sections sec = read_sections(tree);
  std::vector<VerifyNode> nodes = sec.get<VerifyNode>(kBspNodesTag);
  std::vector<std::uint32_t> refs = sec.get<std::uint32_t>(kBspRefsTag);
  const std::uint32_t leaf = leaf_with(nodes, 1);
  const std::uint32_t removed = refs[nodes[leaf].a];
  refs.erase(refs.begin() + nodes[leaf].a);
  for (VerifyNode& n : nodes)
    if (n.plane == VerifyNode::kLeaf && n.a > nodes[leaf].a) --n.a;
  --nodes[leaf].b;
  sec.set(kBspNodesTag, nodes);
  sec.set(kBspRefsTag, refs);
  const std::string bad = temp_path("verify_cli_bad.tree");
  write_sections(bad, soup, sec);
  const Run fail = bsprt_cli("verify " + mesh + " " + bad);
  INFO(fail.output);
  CHECK(fail.status != 0);
  CHECK(fail.output.find("FAILED") != std::string::npos);
  // The node is `leaf`, or (coplanar triangles listed on one side, the CLI's
  // default) a leaf on the other side of the plane the removed triangle lies in.
  CHECK(fail.output.find("; node ") != std::string::npos);
  CHECK(fail.output.find("triangle " + std::to_string(removed)) != std::string::npos);
}
