// The public API (include/bsprt/, docs/api.md) against the CLI's own output:
// the same tree files, rays and hits files, bit for bit. Uses only the public
// headers and links only libbsprt (bsprt::bsprt).
#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <limits>
#include <sstream>
#include <vector>

#if defined(__x86_64__)
#include <xmmintrin.h>
#endif

#include "bsprt/bsprt.h"
#include "test_util.h"

using namespace bsprt;

namespace {

std::vector<char> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

bool same_hits(std::span<const Hit> a, std::span<const Hit> b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(Hit)) == 0);
}

/// Same t (bits) and triangle on every ray: what "certified" promises (the
/// barycentrics u, v are float results of the leaf test, not exact ones).
bool same_t_and_prim(std::span<const Hit> a, std::span<const Hit> b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i].t, &b[i].t, sizeof(float)) != 0 || a[i].prim != b[i].prim) return false;
  return true;
}

/// CLI-written rays, a CLI-built tree of `accel`, and the CLI's hits of `mode` on them.
struct CliRun {
  std::string rays, tree, hits;
};

CliRun cli_trace(const std::string& scene, const std::string& tag, const std::string& kind, const std::string& build,
                 const std::string& mode) {
  CliRun r{test::temp_path("api-" + tag + ".rays"), test::temp_path("api-" + tag + "." + build + ".tree"),
           test::temp_path("api-" + tag + "." + mode + ".hits")};
  REQUIRE(test::bsprt_cli("gen-rays " + scene + " --kind " + kind + " -n 4000 -o " + r.rays).status == 0);
  REQUIRE(test::bsprt_cli("build " + scene + " --accel " + build + " -o " + r.tree).status == 0);
  REQUIRE(test::bsprt_cli("trace " + scene + " " + r.rays + " -o " + r.hits + " --accel " + mode + " --tree " + r.tree)
              .status == 0);
  return r;
}

}  // namespace

TEST_CASE("api: Scene::load counts what the CLI counts", "[api]") {
  const Scene s = Scene::load(test::scene_path("suzanne.obj"));
  CHECK(s.triangle_count() == 968);
  CHECK(s.vertex_count() == 507);
  CHECK(s.summary().degenerate == 0);
  CHECK(s.summary().source == test::scene_path("suzanne.obj"));
  const Box3f b = s.bounds();  // `bsprt info`: [-3.86125, 0.267311, 3.25233] .. [-1.126875, 2.236061, 4.955455]
  CHECK(b.lo.x == Approx(-3.86125));
  CHECK(b.hi.z == Approx(4.955455));
  const test::CliRun info = test::bsprt_cli("info " + test::scene_path("suzanne.obj"));
  REQUIRE(info.status == 0);
  CHECK(info.output.find("triangles   968") != std::string::npos);
  const Scene d = Scene::load("default");
  CHECK(d.triangle_count() == 6400);
  CHECK(d.fingerprint() == Scene::default_scene().fingerprint());
  CHECK_THROWS_AS(Scene::load(test::temp_path("no-such-mesh.obj")), InputError);
  CHECK_THROWS_AS(Scene::load(test::scene_path("stiff_test-nan.obj")), InputError);
  SceneOptions keep;
  keep.allow_nonfinite = true;
  const Scene nan = Scene::load(test::scene_path("stiff_test-nan.obj"), keep);
  CHECK(nan.summary().nonfinite_triangles > 0);
  CHECK(nan.summary().degenerate >= nan.summary().nonfinite_triangles);
}

TEST_CASE("api: Scene::from_arrays equals the loaded scene and rejects bad arrays", "[api]") {
  const Scene s = Scene::load(test::scene_path("suzanne.obj"));
  std::vector<float> v;
  std::vector<std::uint32_t> idx;
  // Rebuild the soup from its corners (3 vertices a triangle): same fingerprint.
  for (std::size_t t = 0; t < s.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Vec3f p = s.corner(t, k);
      v.insert(v.end(), {p.x, p.y, p.z});
      idx.push_back(std::uint32_t(idx.size()));
    }
  const Scene a = Scene::from_arrays(v, idx);
  CHECK(a.fingerprint() == s.fingerprint());
  CHECK(a.triangle_count() == s.triangle_count());
  CHECK(a.summary().unreferenced_vertices == 0);
  CHECK_THROWS_AS(s.corner(968, 0), UsageError);
  CHECK_THROWS_AS(Scene::from_arrays(std::span(v).first(v.size() - 1), idx), UsageError);
  CHECK_THROWS_AS(Scene::from_arrays(v, std::span(idx).first(idx.size() - 1)), UsageError);
  CHECK_THROWS_AS(Scene::from_arrays(v, {}), UsageError);
  std::vector<std::uint32_t> bad = idx;
  bad[5] = std::uint32_t(v.size() / 3);
  CHECK_THROWS_WITH(Scene::from_arrays(v, bad), Catch::Contains("triangle 1 corner 2"));
  std::vector<float> nan = v;
  nan[4] = std::numeric_limits<float>::quiet_NaN();
  CHECK_THROWS_AS(Scene::from_arrays(nan, idx), UsageError);
  SceneOptions keep;
  keep.allow_nonfinite = true;
  const Scene kept = Scene::from_arrays(nan, idx, keep);
  CHECK(kept.summary().nonfinite_triangles == 1);
  CHECK(kept.summary().degenerate == 1);
  // Repeated corners are degenerate, kept and counted, never hit.
  std::vector<std::uint32_t> rep = idx;
  rep[1] = rep[0];
  CHECK(Scene::from_arrays(v, rep).summary().degenerate == 1);
}

TEST_CASE("api: trees built or saved or loaded trace what the CLI traces", "[api]") {
  const std::string path = test::scene_path("suzanne.obj");
  const Scene scene = Scene::load(path);
  for (const char* accel : {"bsp", "kd"}) {
    const std::string mode = accel == std::string("bsp") ? "bsp" : "kd";
    const CliRun cli = cli_trace(path, std::string("trees-") + accel, "vertex", accel, mode);
    const std::vector<Ray> rays = read_rays(cli.rays);
    const std::vector<Hit> expected = read_hits(cli.hits);
    // The CLI's tree file, loaded through the API.
    const Tree loaded = Tree::load(cli.tree, scene);
    CHECK(loaded.kind() == (accel == std::string("bsp") ? TreeKind::Bsp : TreeKind::Kd));
    std::vector<Hit> hits(rays.size());
    Tracer(scene, loaded, "certified").intersect(rays, hits);  // bsp or kd: exact leaves
    CHECK(same_hits(hits, expected));
    // A tree the API builds: saved, it is a tree file the CLI traces to the same hits.
    BuildOptions o;
    o.kind = loaded.kind();
    const Tree built = build(scene, o);
    const std::string saved = test::temp_path(std::string("api-saved.") + accel + ".tree");
    built.save(saved);
    CHECK(file_bytes(saved).size() == built.bytes().size());
    const std::string again = test::temp_path(std::string("api-saved.") + accel + ".hits");
    REQUIRE(test::bsprt_cli("trace " + path + " " + cli.rays + " -o " + again + " --accel " + mode + " --tree " + saved)
                .status == 0);
    CHECK(same_hits(read_hits(again), expected));
    std::vector<Hit> mine(rays.size());
    Tracer(scene, built, "certified").intersect(rays, mine);
    CHECK(same_hits(mine, expected));
  }
}

TEST_CASE("api: Tree::load rejects corrupt files and other scenes", "[api]") {
  const Scene scene = Scene::load(test::scene_path("suzanne.obj"));
  BuildOptions o;
  o.kind = TreeKind::Kd;
  const Tree t = build(scene, o);
  const std::string p = test::temp_path("api-corrupt.tree");
  t.save(p);
  CHECK_THROWS_AS(Tree::load(p, Scene::default_scene()), InputError);
  std::vector<char> bytes = file_bytes(p);
  bytes[bytes.size() / 2] ^= 0x10;
  std::ofstream(p, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
  CHECK_THROWS_WITH(Tree::load(p, scene), Catch::Contains("CRC"));
  CHECK_THROWS_AS(Tree::load(test::temp_path("api-missing.tree"), scene), InputError);
  CHECK_THROWS_AS(t.save("/nonexistent-dir/x.tree"), InputError);
  CHECK_THROWS_AS(Tracer(Scene::default_scene(), t, "float"), UsageError);  // tree of another scene
}

TEST_CASE("api: build reports progress to the total and can be cancelled", "[api]") {
  const Scene scene = Scene::load(test::scene_path("suzanne.obj"));
  for (TreeKind kind : {TreeKind::Bsp, TreeKind::Kd}) {
    BuildOptions o;
    o.kind = kind;
    o.threads = 2;
    double last = -1, total = 0;
    bool monotonic = true;
    o.progress = [&](double done, double tot) {
      monotonic = monotonic && done >= last;
      last = done;
      total = tot;
    };
    const Tree t = build(scene, o);
    CHECK(monotonic);
    CHECK(last == total);
    CHECK(total > 0);
    CHECK(t.build_seconds() > 0);
    BuildOptions c = o;
    std::atomic<int> polls{0};
    c.cancel = [&] { return ++polls >= 2; };
    CHECK_THROWS_AS(build(scene, c), Cancelled);
  }
}

TEST_CASE("api: verify certifies kd and BSP trees as bsprt verify does", "[api]") {
  const std::string path = test::scene_path("suzanne.obj");
  const Scene scene = Scene::load(path);
  for (TreeKind kind : {TreeKind::Bsp, TreeKind::Kd}) {
    BuildOptions o;
    o.kind = kind;
    const Tree t = build(scene, o);
    const Certificate c = verify(scene, t);
    CHECK(c.certified);
    CHECK(c.failure.empty());
    CHECK(c.leaves > 0);
    const std::string saved = test::temp_path(kind == TreeKind::Bsp ? "api-verify.bsp.tree" : "api-verify.kd.tree");
    t.save(saved);
    const test::CliRun cli = test::bsprt_cli("verify " + path + " " + saved);
    CHECK(cli.status == 0);
    CHECK(cli.output.find("CERTIFIED") != std::string::npos);
  }
  CHECK_THROWS_AS(verify(Scene::default_scene(), build(scene)), UsageError);
}

TEST_CASE("api: every mode at every packet width and thread count gives the CLI's hits and occluded agrees", "[api]") {
  const std::string path = test::scene_path("suzanne.obj");
  const Scene scene = Scene::load(path);
  const Tree bsp = build(scene);
  const std::string tree = test::temp_path("api-modes.tree");
  bsp.save(tree);
  const std::string rays_path = test::temp_path("api-modes.rays");
  REQUIRE(test::bsprt_cli("gen-rays " + path + " --kind edge -n 3000 -o " + rays_path).status == 0);
  const std::vector<Ray> rays = read_rays(rays_path);
  const std::pair<const char*, const char*> modes[] = {
      {"certified", "bsp"}, {"float", "bsp-float"}, {"zero-eps", "bsp-zero-eps"}, {"top", "bsp-top"},
      {"top-float", "bsp-top-float"}, {"top-certified", "bsp-top"}};
  std::vector<Hit> ref(rays.size());
  const Tracer exact = Tracer::exact(scene);
  CHECK(exact.certified());
  exact.intersect(rays, ref);
  for (const auto& [mode, accel] : modes) {
    const std::string out = test::temp_path(std::string("api-modes.") + accel + ".hits");
    REQUIRE(test::bsprt_cli("trace " + path + " " + rays_path + " -o " + out + " --accel " + accel + " --tree " + tree)
                .status == 0);
    const std::vector<Hit> expected = read_hits(out);
    const Tracer t(scene, bsp, mode);
    CHECK(t.name() == accel);
    CHECK(t.memory_bytes() > 0);
    CHECK(bsp.scene().fingerprint() == scene.fingerprint());
    for (int threads : {1, 2, 0})
      for (int packets : {1, 8}) {
        std::vector<Hit> hits(rays.size());
        TraceOptions o;
        o.threads = threads;
        o.packet_width = packets;
        t.intersect(rays, hits, o);
        INFO(mode << " threads " << threads << " packets " << packets);
        CHECK(same_hits(hits, expected));
      }
    if (t.certified()) CHECK(same_t_and_prim(expected, ref));  // certified: the exact reference's t and triangle
    std::vector<std::uint8_t> occ(rays.size());
    t.occluded(rays, occ);
    std::size_t agree = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) agree += (occ[i] != 0) == expected[i].hit();
    CHECK(agree == rays.size());
    CHECK(t.occluded(rays[0]) == expected[0].hit());
    CHECK(same_hits(std::vector<Hit>{t.intersect(rays[1])}, std::vector<Hit>{expected[1]}));
  }
  std::vector<Hit> short_out(rays.size() - 1);
  CHECK_THROWS_AS(Tracer(scene, bsp).intersect(rays, short_out), UsageError);
  TraceOptions bad;
  bad.packet_width = 3;
  std::vector<Hit> hits(rays.size());
  CHECK_THROWS_AS(Tracer(scene, bsp).intersect(rays, hits, bad), UsageError);
  CHECK_THROWS_AS(Tracer(scene, bsp, "no-such-mode"), UsageError);
  BuildOptions kd;
  kd.kind = TreeKind::Kd;
  const Tree kd_tree = build(scene, kd);
  CHECK(Tracer(scene, kd_tree, "certified").name() == "kd");  // exact leaves on kd-trees too
  CHECK(Tracer(scene, kd_tree, "float").name() == "kd-float");
  CHECK_THROWS_AS(Tracer(scene, kd_tree, "top"), UsageError);
  CHECK_THROWS_AS(Tracer::by_name(scene, "no-such-accel"), UsageError);
  const std::vector<std::string> names = Tracer::accelerators();
  CHECK(std::find(names.begin(), names.end(), "embree") != names.end());
  // A tree-less accelerator by name: Embree robust, against the CLI.
  const std::string out = test::temp_path("api-modes.embree.hits");
  REQUIRE(test::bsprt_cli("trace " + path + " " + rays_path + " -o " + out + " --accel embree").status == 0);
  Tracer::by_name(scene, "embree").intersect(rays, hits);
  CHECK(same_hits(hits, read_hits(out)));
}

TEST_CASE("api: compare and the ray/hit files agree with bsprt compare", "[api]") {
  const std::string path = test::scene_path("suzanne.obj");
  const Scene scene = Scene::load(path);
  const std::string rays_path = test::temp_path("api-compare.rays");
  REQUIRE(test::bsprt_cli("gen-rays " + path + " --kind random -n 2000 -o " + rays_path).status == 0);
  const std::vector<Ray> rays = read_rays(rays_path);
  const std::string copy = test::temp_path("api-compare-copy.rays");
  write_rays(copy, rays);
  CHECK(file_bytes(copy) == file_bytes(rays_path));
  std::vector<Hit> ref(rays.size()), tested(rays.size());
  Tracer::exact(scene).intersect(rays, ref);
  tested = ref;
  std::size_t first_hit = 0;
  while (first_hit < ref.size() && !ref[first_hit].hit()) ++first_hit;
  REQUIRE(first_hit < ref.size());
  tested[first_hit] = Hit{};  // one lost hit
  const HitComparison c = compare_hits(ref, tested);
  CHECK(c.lost == 1);
  CHECK(c.first_bad_ray == first_hit);
  CHECK_FALSE(c.agrees());
  CHECK(compare_hits(ref, ref).agrees());
  const std::string a = test::temp_path("api-compare-ref.hits"), b = test::temp_path("api-compare-tested.hits");
  write_hits(a, ref);
  write_hits(b, tested);
  const test::CliRun cli = test::bsprt_cli("compare " + a + " " + b);
  CHECK(cli.status == 1);
  CHECK(cli.output.find("lost") != std::string::npos);
  CHECK_THROWS_AS(compare_hits(ref, std::span(tested).first(10)), UsageError);
  CHECK(std::string(version()) == BSPRT_VERSION_STRING);
}

// Found by a review of the C++ API (2026-12-07): a moved-from Scene, Tree or
// Tracer crashed (a null impl) on any call; a kd-tree of a scene of
// degenerate triangles only could be built but not traced or verified (its
// empty root box); out-of-range enum values were taken silently; Embree's
// single-ray error named "ray 0".
TEST_CASE("api: moved-from objects, empty kd trees, bad enums and single-ray errors", "[api][regression]") {
  Scene a = Scene::default_scene();
  const Scene b = std::move(a);
  CHECK_THROWS_WITH(a.triangle_count(), Catch::Contains("bsprt::Scene used after it was moved from"));
  CHECK(b.triangle_count() == 6400);
  Tracer t = Tracer::by_name(b, "brute");
  const Tracer u = std::move(t);
  CHECK_THROWS_AS(t.name(), UsageError);
  CHECK_THROWS_AS(t.intersect(Ray{}), UsageError);
  CHECK(u.name() == "brute");
  BuildOptions kd;
  kd.kind = TreeKind::Kd;
  Tree tree = build(b, kd);
  const Tree moved = std::move(tree);
  CHECK_THROWS_AS(tree.kind(), UsageError);
  CHECK(moved.kind() == TreeKind::Kd);

  const Scene degenerate =
      Scene::from_arrays(std::vector<float>{0, 0, 0, 1, 1, 1, 2, 2, 2}, std::vector<std::uint32_t>{0, 1, 2});
  const Tree empty = build(degenerate, kd);
  Ray r;
  r.org = {-1, 0, 0}, r.dir = {1, 1, 1};
  CHECK_FALSE(Tracer(degenerate, empty).intersect(r).hit());
  CHECK(verify(degenerate, empty).certified);

  BuildOptions bad;
  bad.kind = TreeKind(7);
  CHECK_THROWS_AS(build(b, bad), UsageError);
  bad = BuildOptions{};
  bad.membership = Membership(9);
  CHECK_THROWS_AS(build(b, bad), UsageError);

  Ray below;  // a valid ray Embree cannot trace
  below.org = {0, 0, -5}, below.dir = {0, 0, 1}, below.tnear = -1.0f;
  CHECK_THROWS_WITH(Tracer::by_name(b, "embree").intersect(below), Catch::Contains("embree: the ray has tnear < 0"));
}

TEST_CASE("api: MeshQuery answers what bsprt inside and trace --all-hits write", "[api][inside]") {
  const std::string obj = test::temp_path("api-torus.obj");
  REQUIRE(test::bsprt_cli("gen torus -o " + obj).status == 0);
  const Scene scene = Scene::load(obj);
  const MeshQuery query(scene);
  CHECK(query.open_or_inconsistent_edges() == 0);
  CHECK(MeshQuery(Scene::default_scene()).open_or_inconsistent_edges() > 0);  // the ground grid has a border

  // Points: every corner (on the surface), every centroid (rounded: near it),
  // and a 16^3 grid over the box grown by a tenth (inside the tube and out).
  std::vector<Vec3f> points;
  for (std::size_t t = 0; t < scene.triangle_count(); ++t) {
    const Vec3f a = scene.corner(t, 0), b = scene.corner(t, 1), c = scene.corner(t, 2);
    points.push_back(a);
    points.push_back({(a.x + b.x + c.x) / 3, (a.y + b.y + c.y) / 3, (a.z + b.z + c.z) / 3});
  }
  const Box3f box = scene.bounds();
  const Vec3f lo = box.lo - (box.hi - box.lo) * 0.1f, step = (box.hi - box.lo) * (1.2f / 15);
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 16; ++j)
      for (int k = 0; k < 16; ++k) points.push_back({lo.x + step.x * i, lo.y + step.y * j, lo.z + step.z * k});
  const std::string pts = test::temp_path("api-torus.points"), out = test::temp_path("api-torus.sides");
  {
    std::ofstream f(pts);
    f << std::setprecision(9);  // enough digits that every float reads back as itself
    for (const Vec3f& p : points) f << p.x << ' ' << p.y << ' ' << p.z << '\n';
  }
  const test::CliRun r = test::bsprt_cli("inside " + obj + " " + pts + " -o " + out);
  INFO(r.output);
  REQUIRE(r.status == 0);
  std::vector<PointSide> want;
  {
    std::ifstream in(out);
    for (std::string line; std::getline(in, line);)
      want.push_back(line == "inside" ? PointSide::Inside : line == "outside" ? PointSide::Outside : PointSide::OnSurface);
  }
  REQUIRE(want.size() == points.size());
  std::size_t count[3] = {0, 0, 0};
  for (const PointSide s : want) ++count[int(s)];
  CHECK(count[int(PointSide::Inside)] > 50);
  CHECK(count[int(PointSide::Outside)] > 1000);
  CHECK(count[int(PointSide::OnSurface)] >= scene.triangle_count());  // at least the corners
  for (const int threads : {1, 2, 0}) {
    INFO("threads " << threads);
    std::vector<PointSide> got(points.size());
    QueryOptions o;
    o.threads = threads;
    query.sides(points, got, o);
    CHECK(got == want);
  }
  for (std::size_t i = 0; i < points.size(); i += 97) CHECK(query.side(points[i]) == want[i]);
  for (const char* threads : {"1", "2"}) {  // the CLI's own threads give the same file
    const std::string again = test::temp_path(std::string("api-torus.sides.") + threads);
    REQUIRE(test::bsprt_cli("inside " + obj + " " + pts + " -o " + again + " --threads " + threads).status == 0);
    CHECK(file_bytes(again) == file_bytes(out));
  }

  // All hits: the rows of the CLI's CSV, t bit for bit.
  const std::string rays = test::temp_path("api-torus.rays"), csv = test::temp_path("api-torus.csv");
  REQUIRE(test::bsprt_cli("gen-rays " + obj + " --kind vertex -n 2000 --seed 5 -o " + rays).status == 0);
  REQUIRE(test::bsprt_cli("trace " + obj + " " + rays + " --all-hits -o " + csv).status == 0);
  std::vector<Crossing> rows;
  {
    std::ifstream in(csv);
    std::string line;
    std::getline(in, line);
    REQUIRE(line == "ray,prim,t,side");
    while (std::getline(in, line)) {
      std::istringstream s(line);
      std::string field[4];
      for (auto& f : field) std::getline(s, f, ',');
      rows.push_back(Crossing{std::stoull(field[0]), std::uint32_t(std::stoul(field[1])), std::strtof(field[2].c_str(), nullptr),
                              std::stoi(field[3])});
    }
  }
  const std::vector<Ray> rs = read_rays(rays);
  CHECK(rows.size() > rs.size());  // rays aimed at vertices cross the torus at least twice
  const auto same = [](const std::vector<Crossing>& a, const std::vector<Crossing>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a[i].ray != b[i].ray || a[i].prim != b[i].prim || std::memcmp(&a[i].t, &b[i].t, sizeof(float)) != 0 ||
          a[i].side != b[i].side)
        return false;
    return true;
  };
  for (const int threads : {1, 0}) {
    QueryOptions o;
    o.threads = threads;
    CHECK(same(query.all_hits(rs, o), rows));
  }
  std::vector<Crossing> first;  // crossings() of one ray: that ray's rows, with ray = 0
  for (const Crossing& x : rows)
    if (x.ray == 7) first.push_back(Crossing{0, x.prim, x.t, x.side});
  CHECK(!first.empty());
  CHECK(same(query.crossings(rs[7]), first));
  int sum = 0;  // a whole line through a closed mesh leaves it as often as it enters
  Ray line = rs[7];
  line.tnear = -std::numeric_limits<float>::infinity();
  for (const Crossing& x : query.crossings(line)) sum += x.side;
  CHECK(sum == 0);

  // Bad input: a clear UsageError, before anything is answered.
  std::vector<Vec3f> bad = {points[0], {0.0f, std::nanf(""), 0.0f}};
  std::vector<PointSide> two(2), one(1);
  CHECK_THROWS_WITH(query.sides(bad, two), Catch::Contains("point 1 has a NaN or infinite coordinate"));
  CHECK_THROWS_AS(query.side(bad[1]), UsageError);
  CHECK_THROWS_WITH(query.sides(points, one), Catch::Contains("room for 1 answers"));
  QueryOptions negative;
  negative.threads = -1;
  CHECK_THROWS_AS(query.all_hits(rs, negative), UsageError);
  MeshQuery moved = query;
  const MeshQuery kept = std::move(moved);
  CHECK_THROWS_WITH(moved.side(points[0]), Catch::Contains("moved from"));
  CHECK(kept.side(points[0]) == PointSide::OnSurface);
}

#if defined(__x86_64__)
// Found 2026-12-07 (tests/test_fp_env.cpp): with flush-to-zero and
// denormals-are-zero set on the calling thread (as Embree advises its users),
// the exact reference missed every ray of a scene with subnormal coordinates.
// Every public function now computes in IEEE arithmetic and gives the caller
// its own settings back.
TEST_CASE("api: a caller with flush-to-zero and denormals-are-zero gets the same trees, certificate and hits", "[api]") {
  const float grid[12][3] = {{0, 5, 1}, {1, 5, 0}, {1, 6, 2}, {3, 4, 2},   {3, 5, 2}, {4, 5, 2},
                             {1, 2, 3}, {1, 2, 5}, {2, 2, 5}, {2, 1, 4.5f}, {4, 1, 6.5f}, {2, 1, 4}};
  std::vector<float> vertices;
  for (const auto& g : grid)
    for (const float c : g) vertices.push_back(std::ldexp(c, -140));  // subnormal floats
  const std::vector<std::uint32_t> indices = {5, 4, 3, 6, 8, 7, 2, 1, 0, 9, 10, 11};
  std::vector<bsprt::Ray> rays;  // made here, in IEEE arithmetic: FTZ would flush these directions
  for (std::uint32_t t = 0; t < 12; ++t) {
    bsprt::Ray r;
    r.org = {std::ldexp(-1.0f, -140), std::ldexp(-1.0f, -140), std::ldexp(-1.0f, -140)};
    r.dir = bsprt::Vec3f{vertices[3 * t], vertices[3 * t + 1], vertices[3 * t + 2]} - r.org;
    rays.push_back(r);
  }
  std::vector<bsprt::Vec3f> points;  // the corners (on the surface), made here in IEEE arithmetic too
  for (std::uint32_t v = 0; v < 12; ++v) points.push_back({vertices[3 * v], vertices[3 * v + 1], vertices[3 * v + 2]});
  struct Outcome {
    std::vector<std::byte> kd;  // (a BSP file holds its build time)
    bool certified = false;
    std::vector<bsprt::Hit> exact, single, batch;
    std::size_t degenerate = 0;
    std::vector<bsprt::PointSide> sides;
    std::size_t crossings = 0;
  };
  const auto run = [&] {
    Outcome o;
    const bsprt::Scene scene = bsprt::Scene::from_arrays(vertices, indices);
    o.degenerate = scene.summary().degenerate;
    const bsprt::Tree bsp = bsprt::build(scene);
    bsprt::BuildOptions kd_options;
    kd_options.kind = bsprt::TreeKind::Kd;
    const bsprt::Tree kd = bsprt::build(scene, kd_options);
    o.kd.assign(kd.bytes().begin(), kd.bytes().end());
    o.certified = bsprt::verify(scene, bsp).certified;
    const bsprt::Tracer exact = bsprt::Tracer::exact(scene);
    const bsprt::Tracer tracer(scene, bsp);
    o.exact.resize(rays.size());
    exact.intersect(rays, o.exact);
    for (const bsprt::Ray& r : rays) o.single.push_back(tracer.intersect(r));
    o.batch.resize(rays.size());
    tracer.intersect(rays, o.batch);
    const bsprt::MeshQuery query(scene);  // the exact inside and all-hits queries too
    o.sides.resize(points.size());
    query.sides(points, o.sides);
    o.crossings = query.all_hits(rays).size();
    return o;
  };
  struct Mxcsr {  // sets MXCSR, and restores it also when a check throws
    unsigned saved = _mm_getcsr();
    explicit Mxcsr(unsigned value) { _mm_setcsr(value); }
    ~Mxcsr() { _mm_setcsr(saved); }
  };
  REQUIRE(rays.front().dir.y == std::ldexp(6.0f, -140));  // 5 - (-1), kept as a subnormal
  Outcome want, got;
  unsigned after = 0;
  {
    const Mxcsr ieee(0x1F80u);
    want = run();
  }
  {
    const Mxcsr ftz_daz(0x1F80u | 0x8040u);
    got = run();
    after = _mm_getcsr();
  }
  CHECK((after & 0x8040u) == 0x8040u);  // the caller's settings are its own again
  REQUIRE(want.certified);
  CHECK(got.certified);
  CHECK(got.degenerate == want.degenerate);
  CHECK(want.sides == std::vector<bsprt::PointSide>(want.sides.size(), bsprt::PointSide::OnSurface));
  CHECK(got.sides == want.sides);
  CHECK(want.crossings > 0);
  CHECK(got.crossings == want.crossings);
  CHECK(got.kd == want.kd);
  int hits = 0;
  for (std::size_t i = 0; i < want.exact.size(); ++i) {
    CAPTURE(i);
    hits += want.exact[i].hit();
    CHECK(got.exact[i].prim == want.exact[i].prim);
    CHECK(got.exact[i].t == want.exact[i].t);
    CHECK(got.single[i].prim == want.exact[i].prim);
    CHECK(got.single[i].t == want.exact[i].t);
    CHECK(got.batch[i].prim == want.exact[i].prim);
    CHECK(got.batch[i].t == want.exact[i].t);
  }
  CHECK(hits >= 10);
}
#endif
