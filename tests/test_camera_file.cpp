// Camera files (geometry/io/camera_file.h, docs/rendering.md "Camera files"):
// the project's bench/cameras.json, names, and bad files with clear errors.
#include <catch2/catch.hpp>

#include <fstream>
#include <vector>
#include <string>

#include "bsprt/error.h"
#include "geometry/io/camera_file.h"
#include "geometry/scenes/camera.h"
#include "test_util.h"

using namespace bsprt;

namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string p = test::temp_path(name);
  std::ofstream(p) << text;
  return p;
}

const std::string kProjectCameras = std::string(BSPRT_SOURCE_DIR) + "/bench/cameras.json";

}  // namespace

TEST_CASE("camera file: bench/cameras.json holds the interior views", "[camera]") {
  const std::vector<NamedCamera> cams = read_camera_file(kProjectCameras);
  REQUIRE(cams.size() >= 2);
  const NamedCamera* sponza = camera_for_scene(cams, "sponza.obj");
  REQUIRE(sponza != nullptr);
  CHECK(sponza->name == "sponza-atrium");
  CHECK(sponza->camera.fov == 65.0f);
  CHECK(camera_for_scene(cams, "conference-331k.obj") != nullptr);
  CHECK(camera_for_scene(cams, "stanford-bunny.obj") == nullptr);
  CHECK(camera_from_spec(kProjectCameras + ":conference-room").scene == "conference-331k.obj");
  CHECK_THROWS_WITH(camera_from_spec(kProjectCameras + ":nope"), Catch::Contains("sponza-atrium"));
  CHECK_THROWS_AS(camera_from_spec(kProjectCameras), UsageError);  // two cameras: a name is needed
}

TEST_CASE("camera file: one camera needs no name, and bad files name the file and the problem", "[camera]") {
  const std::string one = write_temp("cam-one.json",
                                     R"({"cameras": [{"name": "a", "vp": [0, 0, -5], "vi": [0, 0, 0], "vu": [0, 1, 0], "fov": 45}]})");
  const NamedCamera c = camera_from_spec(one);
  CHECK(c.camera.vp.z == -5.0f);
  CHECK(c.camera.fov == 45.0f);
  const std::pair<std::string, std::string> bad[] = {
      {"{\"cameras\": [\n{\"name\": \"a\",\n \"vp\": [0, 0, 0] \"vi\": [1, 0, 0]}]}", ":3: not valid JSON"},
      {R"({"views": []})", "array \"cameras\""},
      {R"({"cameras": []})", "no cameras"},
      {R"({"cameras": [{"vp": [0, 0, 0]}]})", "\"name\""},
      {R"({"cameras": [{"name": "a", "vi": [1, 0, 0], "vu": [0, 1, 0], "fov": 60}]})", "\"vp\" is missing"},
      {R"({"cameras": [{"name": "a", "vp": [0, 0], "vi": [1, 0, 0], "vu": [0, 1, 0], "fov": 60}]})", "3 numbers"},
      {R"({"cameras": [{"name": "a", "vp": [0, 0, 0], "vi": [0, 0, 0], "vu": [0, 1, 0], "fov": 60}]})", "same point"},
      {R"({"cameras": [{"name": "a", "vp": [0, 0, 0], "vi": [0, 1, 0], "vu": [0, 2, 0], "fov": 60}]})", "parallel"},
      {R"({"cameras": [{"name": "a", "vp": [0, 0, 0], "vi": [1, 0, 0], "vu": [0, 1, 0], "fov": 180}]})", "(0, 180)"},
      {R"({"cameras": [{"name": "a", "vp": [0, 0, 0], "vi": [1, 0, 0], "vu": [0, 1, 0], "fov": 60},
                       {"name": "a", "vp": [0, 0, 0], "vi": [1, 0, 0], "vu": [0, 1, 0], "fov": 60}]})", "used twice"},
  };
  int i = 0;
  for (const auto& [text, what] : bad) {
    const std::string p = write_temp("cam-bad-" + std::to_string(i++) + ".json", text);
    INFO(text);
    CHECK_THROWS_AS(read_camera_file(p), InputError);
    CHECK_THROWS_WITH(read_camera_file(p), Catch::Contains(p) && Catch::Contains(what));
  }
  CHECK_THROWS_AS(read_camera_file(test::temp_path("cam-missing.json")), InputError);
}

// The interior views are inside: almost every primary ray hits (sponza's atrium
// is open to the sky above, the conference room is closed).
TEST_CASE("camera file: the interior cameras see walls all around", "[camera][cli]") {
  const std::pair<std::string, double> views[] = {{"sponza-atrium", 0.9}, {"conference-room", 0.99}};
  for (const auto& [name, least] : views) {
    const NamedCamera c = camera_from_spec(kProjectCameras + ":" + name);
    const std::string rays = test::temp_path("cam-" + name + ".rays"), hits = test::temp_path("cam-" + name + ".hits");
    REQUIRE(test::bsprt_cli("gen-rays " + test::scene_path(c.scene) + " --kind primary --camera " + kProjectCameras +
                            ":" + name + " --size 64 48 -o " + rays).status == 0);
    const test::CliRun t =
        test::bsprt_cli("trace " + test::scene_path(c.scene) + " " + rays + " -o " + hits + " --accel embree");
    REQUIRE(t.status == 0);
    const std::size_t at = t.output.find(" rays, ");
    REQUIRE(at != std::string::npos);
    const double hit = std::stod(t.output.substr(at + 7));
    INFO(name << ": " << t.output);
    CHECK(hit >= least * 64 * 48);
  }
}

// Found by an adversarial review of the readers (2026-12-07): misspelt keys
// and repeated keys were ignored, and cameras whose basis overflowed in float
// passed the checks and made NaN rays (far points) or identical rays (a huge
// up vector).
TEST_CASE("camera file: unknown and repeated keys are errors, and far or huge vectors make usable rays",
          "[camera][regression]") {
  const std::string ok = R"({"name": "a", "vp": [0, 0, 5], "vi": [0, 0, 0], "vu": [0, 1, 0], "fov": 40)";
  CHECK_NOTHROW(read_camera_file(write_temp("cam_ok.json", R"({"cameras": [)" + ok + "}]}")));
  CHECK_THROWS_WITH(read_camera_file(write_temp("cam_typo.json", R"({"cameras": [)" + ok + R"(, "fov_deg": 30}]})")),
                    Catch::Contains("unknown key \"fov_deg\""));
  CHECK_THROWS_WITH(read_camera_file(write_temp("cam_dup.json", R"({"cameras": [)" + ok + R"(, "fov": 170}]})")),
                    Catch::Contains("the key \"fov\" is given twice"));
  CHECK_THROWS_WITH(read_camera_file(write_temp("cam_top.json", R"({"camera": 1, "cameras": [)" + ok + "}]}")),
                    Catch::Contains("unknown top-level key \"camera\""));
  CHECK_THROWS_WITH(read_camera_file(write_temp("cam_what.json", R"({"cameras": [)" + ok + R"(, "what": 3}]})")),
                    Catch::Contains("\"what\" must be a string"));

  for (const Camera cam : {Camera{{0.3f, 0.3f, 3e38f}, {0.3f, 0.3f, -3e38f}, {0, 1, 0}, 40.0f},
                           Camera{{0, 0, 5}, {0, 0, 0}, {0, 1e30f, 0}, 40.0f},
                           Camera{{-3e38f, 0, 0}, {3e38f, 1, 0}, {0, 0, 3e38f}, 60.0f}}) {
    REQUIRE(camera_problem(cam).empty());
    const CameraRays rays(cam, 4, 4);
    std::vector<Vec3f> dirs;
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) {
        const Ray r = rays.ray(x, y);
        CHECK(is_valid(r));
        dirs.push_back(normalize(r.dir));
      }
    CHECK(length(dirs.front() - dirs.back()) > 0.1f);  // the corners of the image look different ways
  }
}
