// Bad and odd input to the bsprt CLI, found by an adversarial review
// (2026-12-07): each case crashed, ended in an "internal error", wrote
// NaN rays or a black image, or silently ignored what it was given. Each now
// gets a usage error (exit 2) or an input error naming the file (exit 1),
// before any work where the arguments alone decide it.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "bsprt/io.h"
#include "test_util.h"

using namespace bsprt;
using bsprt::test::bsprt_cli;
using bsprt::test::scene_path;
using bsprt::test::temp_path;
using Run = bsprt::test::CliRun;

namespace {
bool has(const Run& r, const std::string& text) { return r.output.find(text) != std::string::npos; }
}  // namespace

TEST_CASE("cli: counts, sizes, thread numbers and modes out of range are usage errors before any work",
          "[cli][regression]") {
  const std::string cube = scene_path("cube.obj"), rays = temp_path("cli_in.rays");
  REQUIRE(bsprt_cli("gen-rays " + cube + " -n 50 -o " + rays).status == 0);
  struct Case {
    std::string args, message;
  };
  const std::string hits = " -o " + temp_path("cli_in.hits");
  const std::string png = " -o " + temp_path("cli_in.png");
  for (const Case& c : {
           // oneTBB's arenas crashed (a segfault) above 65535 threads; -3 meant all cores.
           Case{"trace " + cube + " " + rays + hits + " --threads 70000",
                "--threads: must be a whole number from 0 to 4096"},
           Case{"trace " + cube + " " + rays + hits + " --threads=-3", "--threads"},
           Case{"build " + cube + " -o " + temp_path("x.bsp") + " --threads 70000", "--threads"},
           Case{"verify " + cube + " " + temp_path("x.bsp") + " --threads 99999", "--threads"},
           Case{"render" + png + " --threads 100000", "--threads"},
           // An unsigned -n wrapped -5 around to 2^64 - 5 ("cannot create std::vector larger than max_size()").
           Case{"gen-rays " + cube + " -o " + rays + ".x -n -5", "--count: must be a whole number from 1"},
           Case{"gen-rays " + cube + " -o " + rays + ".x -n 99999999999999999999", "--count"},
           Case{"gen-rays " + cube + " -o " + rays + ".x -n 0", "--count"},  // wrote 1 ray
           Case{"gen-rays " + cube + " --kind primary --size -3 4 -o " + rays + ".x", "--size"},
           Case{"gen-rays " + cube + " --size 4 4 -o " + rays + ".x", "--size is for --kind primary"},  // was ignored
           Case{"render --size 0 0" + png, "--size"},  // wrote a 0x0 image
           Case{"render --size -4 4" + png, "--size"},
           Case{"render --fov 0" + png, "--fov: must be a number in (0, 180)"},  // 0, -5 and nan were ignored
           Case{"render --fov nan" + png, "--fov"}, Case{"render --fov 200" + png, "--fov"},
           Case{"render --mode heat --heat-max -1" + png, "--heat-max"},
           Case{"render --mode bogus" + png, "--mode"},  // loaded the scene and built the tree first
           Case{"render -o " + temp_path("cli_in.jpg"), "render writes .png or .pfm images, not '.jpg'"},
           Case{"render --spp 4" + png, "--spp: for --mode path only"},
           Case{"render --mode path --heat-metric tests" + png, "--heat-metric: for --mode heat only"},
           Case{"trace --passes 0 " + cube + " " + rays + hits, "--passes: must be a whole number from 1"},
           Case{"bench " + cube + " --modes kd,kd --count 10 -o " + temp_path("cli_in_bench"),
                "--modes lists kd twice"},
           Case{"bench " + cube + " --prefix ../x --count 10 -o " + temp_path("cli_in_bench"),
                "--prefix must be a plain file name"},
           Case{"info ''", "SCENE is an empty string"},  // loaded the embedded default scene
           Case{"render --camera ''" + png, "--camera: must not be an empty path"},  // were ignored
           Case{"trace " + cube + " " + rays + hits + " --tree ''", "--tree: must not be an empty path"},
       }) {
    const Run r = bsprt_cli(c.args);
    INFO(c.args << "\n" << r.output);
    CHECK(r.status == 2);
    CHECK(has(r, c.message));
    CHECK_FALSE(has(r, "internal error"));
    CHECK_FALSE(has(r, "scene:"));  // refused before loading anything
  }
  // --passes 0 used to print its bound with 300 digits.
  CHECK_FALSE(has(bsprt_cli("trace --passes 0 " + cube + " " + rays + hits), "1797693"));
}

TEST_CASE("cli: a directory or a file where the other is expected is an error naming the path", "[cli][regression]") {
  const std::string cube = scene_path("cube.obj"), dir = temp_path("cli_in_dir");
  std::filesystem::create_directories(dir);
  const std::string rays = temp_path("cli_in_dir.rays");
  REQUIRE(bsprt_cli("gen-rays " + cube + " -n 20 -o " + rays).status == 0);
  for (const std::string& args :
       {"render --camera " + dir + " -o " + temp_path("cli_in_dir.png"),
        "gen-rays " + cube + " --kind primary --camera " + dir + " -o " + rays + ".x",
        "trace " + cube + " " + rays + " --tree " + dir + " -o " + temp_path("d.hits"), "verify " + cube + " " + dir,
        "bench " + cube + " --cameras " + dir + " --count 10 -o " + dir}) {
    const Run r = bsprt_cli(args);
    INFO(args << "\n" << r.output);
    CHECK(r.status == 1);
    CHECK(has(r, dir + ": is a directory"));
    CHECK_FALSE(has(r, "internal error"));
  }
  // bench -o naming an existing file failed after all the work, with a filesystem_error.
  const Run b = bsprt_cli("bench " + cube + " --count 10 -o " + cube);
  INFO(b.output);
  CHECK(b.status == 1);
  CHECK(has(b, "cannot make the output directory"));
  CHECK_FALSE(has(b, "bench: scene"));  // before loading the scenes
}

TEST_CASE("cli: a scene of degenerate triangles only gives no NaN rays and no blind camera", "[cli][regression]") {
  const std::string obj = temp_path("cli_in_degenerate.obj");
  std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 1 2\nf 1 2 2\n";
  const std::string rays = temp_path("cli_in_degenerate.rays");
  for (const std::string& args : {"gen-rays " + obj + " -o " + rays, "gen-rays " + obj + " --kind primary -o " + rays,
                                  "gen-rays " + obj + " --kind primary --size 4 4 -o " + rays,
                                  "render " + obj + " --size 8 8 -o " + temp_path("cli_in_degenerate.png")}) {
    const Run r = bsprt_cli(args);
    INFO(args << "\n" << r.output);
    CHECK(r.status == 2);
    CHECK(has(r, "no non-degenerate triangle"));
  }
  // A camera given by the options needs no framing: an empty picture, honestly.
  const Run placed =
      bsprt_cli("render " + obj + " --size 8 8 --vp 0 0 -3 --vi 0 0 0 -o " + temp_path("cli_in_degenerate.png"));
  INFO(placed.output);
  CHECK(placed.status == 0);
  CHECK(has(placed, "0 of 64 rays hit"));
}

TEST_CASE("cli: render refuses a camera that sees nothing and an unwritable --json", "[cli][regression]") {
  const std::string png = " --size 8 8 -o " + temp_path("cli_in_cam.png");
  const std::string cams = temp_path("cli_in_cam.json");
  std::ofstream(cams)
      << R"({"cameras": [{"name": "a:b", "vp": [0, 0, -5], "vi": [0, 0, 0], "vu": [0, 1, 0], "fov": 40}]})";
  struct Case {
    std::string args, message;
  };
  for (const Case& c : {Case{"render --vp 0 0 3 --vi 0 0 3" + png, "vp and vi are the same point"},
                        Case{"render --vu 0 0 0" + png, "vu is parallel to the view direction (or zero)"},
                        Case{"render --camera " + cams + " --vu 0 0 5" + png, "vu is parallel"},
                        Case{"render --vp nan 0 0" + png, "vp (the position) is not finite"},
                        Case{"render --vp inf 0 0" + png, "not finite"}}) {
    const Run r = bsprt_cli(c.args);
    INFO(c.args << "\n" << r.output);
    CHECK(r.status == 2);
    CHECK(has(r, c.message));
  }
  // A camera name may hold ':' (FILE:NAME splits at the file).
  const Run named = bsprt_cli("render --camera " + cams + ":a:b" + png);
  INFO(named.output);
  CHECK(named.status == 0);
  // The file's cameras are checked the same way; "fov" as a string is not "missing".
  std::ofstream(cams)
      << R"({"cameras": [{"name": "c", "vp": [0, 0, -5], "vi": [0, 0, 0], "vu": [0, 1, 0], "fov": "45"}]})";
  const Run s = bsprt_cli("render --camera " + cams + png);
  CHECK(s.status == 1);
  CHECK(has(s, "\"fov\" must be a number"));
  // --json that cannot be written was silently skipped (exit 0). A missing
  // folder is now a usage error before any work; a folder that exists but
  // cannot be written to still fails, after the render, with exit 1.
  const Run j = bsprt_cli("render --mode path --spp 1 --bounces 0 --json " + temp_path("no_such_dir/x.json") + png);
  INFO(j.output);
  CHECK(j.status == 2);
  CHECK(has(j, "does not exist"));
  const Run w = bsprt_cli("render --mode path --spp 1 --bounces 0 --json /proc/bsprt_x.json" + png);
  INFO(w.output);
  CHECK(w.status == 1);
  CHECK(has(w, "cannot write the --json summary"));
}

TEST_CASE("cli: trace --all-hits refuses options it would ignore and prints JSON with --json", "[cli][regression]") {
  const std::string cube = scene_path("cube.obj"), rays = temp_path("cli_in_all.rays");
  REQUIRE(bsprt_cli("gen-rays " + cube + " -n 40 -o " + rays).status == 0);
  const std::string out = " -o " + temp_path("cli_in_all.csv");
  for (const std::string& opt : {"--packets 16", "--passes 3", "--single-rays sequential", "--membership closed"}) {
    const Run r = bsprt_cli("trace " + cube + " " + rays + out + " --all-hits " + opt);
    INFO(opt << "\n" << r.output);
    CHECK(r.status == 2);
    CHECK(has(r, "not used by --all-hits"));
  }
  const Run j = bsprt_cli("trace " + cube + " " + rays + out + " --all-hits --json");
  INFO(j.output);
  CHECK(j.status == 0);
  CHECK(has(j, "{\"all_hits\": true, \"rays\": 40, \"invalid_rays\": 0, \"crossings\": "));
}

TEST_CASE("cli: compare reports a wrong t on the right triangle, refuses malformed records and tolerances",
          "[cli][regression]") {
  const std::string ref = temp_path("cli_in_ref.hits"), got = temp_path("cli_in_got.hits");
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<Hit> reference = {Hit{1.0f, 0, 0.25f, 0.25f}, Hit{}, Hit{2.0f, 3, 0.5f, 0.0f}};
  write_hits(ref, reference);
  // write_hits refuses malformed records: write valid ones, then put the
  // tested records' bytes in place (records are the file's last bytes).
  const auto compare = [&](std::vector<Hit> tested, const std::string& extra = "") {
    write_hits(got, std::vector<Hit>(tested.size()));
    std::fstream f(got, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(-std::streamoff(tested.size() * sizeof(Hit)), std::ios::end);
    f.write(reinterpret_cast<const char*>(tested.data()), std::streamsize(tested.size() * sizeof(Hit)));
    f.close();
    return bsprt_cli("compare " + ref + " " + got + " " + extra);
  };
  CHECK(compare(reference).status == 0);
  std::vector<Hit> tripled = reference;
  tripled[2].t = 6.0f;  // the right triangle at three times its t: counted "same triangle" before
  const Run t = compare(tripled);
  INFO(t.output);
  CHECK(t.status == 1);
  CHECK(has(t, "same triangle at a t beyond tolerance 1"));
  CHECK(has(t, "first disagreement at ray 2"));
  for (const Hit& bad : {Hit{std::nanf(""), 0, 0, 0}, Hit{inf, 0, 0, 0}, Hit{-inf, 0, 0, 0}, Hit{5.0f, kNoHit, 0, 0}}) {
    std::vector<Hit> tested = reference;
    tested[1] = bad;
    const Run r = compare(tested);
    INFO(bad.t << " " << bad.prim << "\n" << r.output);
    CHECK(r.status == 1);
    CHECK(has(r, got + ": hit record 1 is a"));
  }
  for (const std::string& tol : {"-1", "nan"}) {
    const Run r = compare(reference, "--tolerance " + tol);
    CHECK(r.status == 2);
    CHECK(has(r, "--tolerance"));
  }
  const Run n = compare({reference[0]});
  CHECK(n.status == 2);
  CHECK(has(n, ref));
  CHECK(has(n, got));
}

TEST_CASE("cli: inside reads points as the nearest floats, counts them, and names bad lines", "[cli][regression]") {
  const std::string cube = scene_path("cube.obj"), out = temp_path("cli_in_inside.txt");
  const std::string points = temp_path("cli_in_inside_points.txt");
  // 0.50000001 and 0.49999999 round to 0.5, the cube's face: surface, and said to be rounded.
  // 1e-400 is below double's range: 0, rounded (it was "overflows float"); a
  // leading '+' reads as in mesh files (it was "not a number"). Review of 2026-12-07.
  std::ofstream(points) << "0.50000001 0 0\n0.49999999 0 0  # a comment after a point\n# a whole-line comment\n\n"
                           "0 0 0\n1e-400 +0.25 -1e-400\n";
  const Run r = bsprt_cli("inside " + cube + " " + points + " -o " + out);
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(has(r, "4 points (3 with a coordinate rounded to the nearest float, as mesh coordinates are)"));
  std::ifstream in(out);
  std::string a, b, c, d;
  in >> a >> b >> c >> d;
  CHECK(a == "surface");
  CHECK(b == "surface");
  CHECK(c == "inside");
  CHECK(d == "inside");
  struct Case {
    std::string text, message;
  };
  for (const Case& k : {Case{"0 0 0\n1e39 0 0\n", ":2: \"1e39\" overflows float"},
                        Case{"nan 0 0\n", ":1: \"nan\" is not finite"},
                        Case{"0 1e400 0\n", ":1: \"1e400\" overflows float"},
                        Case{"0 ++1 0\n", ":1: \"++1\" is not a number"},
                        Case{std::string("0 0 \0 0\n", 8), ":1: expected three numbers \"x y z\", got \"0 0 ? 0\""},
                        Case{"1 2\n", ":1: expected three numbers"}}) {
    std::ofstream(points, std::ios::binary | std::ios::trunc) << k.text;
    const Run e = bsprt_cli("inside " + cube + " " + points + " -o " + out);
    INFO(e.output);
    CHECK(e.status == 1);
    CHECK(has(e, points + k.message));
  }
}

TEST_CASE("cli: gen refuses ray options without --rays-out, and PLY layouts OpenMesh misreads are named",
          "[cli][regression]") {
  const Run g = bsprt_cli("gen fan --rays bogus -o " + temp_path("cli_in_fan.obj"));
  CHECK(g.status == 2);
  const Run h = bsprt_cli("gen fan --rays edge -o " + temp_path("cli_in_fan.obj"));  // wrote the scene, no rays
  CHECK(h.status == 2);
  CHECK(has(h, "ray options need --rays-out"));
  const std::string ply = temp_path("cli_in_face_first.ply");
  const auto refused = [&](const std::string& text, const std::string& message) {
    std::ofstream(ply) << text;
    const Run r = bsprt_cli("info " + ply);
    CHECK(r.status == 1);
    CHECK(has(r, ply + message));
  };
  refused("ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
          "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
          "3 0 1 2\n0 0 0\n1 0 0\n0 1 0\n",
          ":3: PLY face element before the vertex element is not supported");
  refused("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
          "property float z\nelement face 1\nproperty uchar flags\nproperty list uchar int vertex_indices\n"
          "end_header\n0 0 0\n1 0 0\n0 1 0\n7 3 0 1 2\n",
          ":7: PLY face property 'flags' before vertex_indices is not supported");
}

// Found by an adversarial review of the readers (2026-12-07): invalid rays
// became misses without being counted anywhere.
TEST_CASE("cli: trace counts and reports invalid rays", "[cli][regression]") {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  std::vector<Ray> rays(5);
  for (Ray& r : rays) r.org = {0, 0, -5}, r.dir = {0, 0, 1};
  rays[1].dir = {nan, 0, 1};
  rays[2].dir = {0, 0, 0};
  rays[3].org = {inf, 0, 0};
  rays[4].tnear = 2, rays[4].tfar = 1;
  const std::string path = temp_path("cli_invalid.rays"), hits = temp_path("cli_invalid.hits");
  write_rays(path, rays);
  const Run t = bsprt_cli("trace default " + path + " -o " + hits + " --accel brute");
  CHECK(t.status == 0);
  CHECK(t.output.find("note: 4 rays of " + path + " are not valid") != std::string::npos);
  const Run j = bsprt_cli("trace default " + path + " -o " + hits + " --accel brute --json");
  CHECK(j.output.find("\"invalid_rays\": 4") != std::string::npos);
  const Run ok = bsprt_cli("trace default " + path + " -o " + hits + " --all-hits --json");
  CHECK(ok.output.find("\"invalid_rays\": 4") != std::string::npos);
}

// Found by reviews of the docs and of bench/render/gen (2026-12-07): outputs
// naming a directory failed only after all the work, and options a command
// would ignore were accepted (README: "refused rather than dropped").
TEST_CASE("cli: output paths are checked before any work, and ignored options are refused", "[cli][regression]") {
  const std::string dir = temp_path("cli_out_dir.hits"), rays = temp_path("cli_out.rays");
  std::filesystem::create_directories(dir);
  REQUIRE(bsprt_cli("gen-rays default -n 20 -o " + rays).status == 0);
  struct Case {
    std::string args, message;
  };
  for (const Case& c : {
           Case{"trace default " + rays + " -o " + dir, "is a directory; give a file to write"},
           Case{"build default -o " + dir, "is a directory; give a file to write"},
           Case{"render default --size 8 8 -o " + temp_path("no_such_folder") + "/x.png", "does not exist"},
           Case{"render default --size 8 8 --json " + dir + " -o " + temp_path("cli_out.png"), "is a directory"},
           Case{"trace default " + rays + " -o " + temp_path("cli_out.hits") + " --accel bvh8 --packets 16",
                "bvh8 traces single rays only"},
           Case{"render default --mode heat --packets 8 --size 8 8 -o " + temp_path("cli_heat.png"),
                "--packets: not used by --mode heat"},
           Case{"render default --mode heat --heat-compare kd --heat-max 2 --size 8 8 -o " + temp_path("cli_heat.png"),
                "--heat-max: a difference map"},
           Case{"render default --mode heat --accel embree --heat-metric tests --size 8 8 -o " + temp_path("cli_heat.png"),
                "embree does not count"},
           Case{"gen-rays default --kind primary --seed 5 -o " + rays, "--seed: primary rays are not random"},
           Case{"gen slivers --detail 2 -o " + temp_path("cli_slivers.obj"), "has no tessellation level"},
           Case{"bench default --rays vertex,vertex --modes kd -o " + temp_path("cli_bench_dup"), "--rays lists vertex twice"},
           Case{"bench default --rays vertex --modes bsp-certified -o " + temp_path("cli_bench_old"), "is now 'bsp'"}}) {
    const Run r = bsprt_cli(c.args);
    INFO(c.args << "\n" << r.output);
    CHECK(r.status == 2);
    CHECK(has(r, c.message));
  }
  CHECK_FALSE(std::filesystem::exists(temp_path("cli_bench_old")));  // refused before -o was made
}
