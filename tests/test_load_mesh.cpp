// Mesh loading (geometry/load_mesh.h): small files of every format written
// here, checked triangle by triangle against formats.md's numbering; every
// malformed case throwing InputError that names the file; the shared scenes'
// counts from shared/scenes/SOURCES.md. Also the exact degeneracy test and
// TriangleSoup's helpers.
#include <catch2/catch.hpp>
#include <sys/stat.h>

#include <filesystem>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "bsprt/error.h"
#include "geometry/io/load_mesh.h"
#include "robust/degenerate.h"
#include "test_util.h"

using namespace bsprt;

namespace {

std::string write_file(const std::string& name, const std::string& bytes) {
  const std::string path = test::temp_path(name);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

/// The message of the InputError load_mesh throws, or "" if it loads.
std::string load_error(const std::string& path, bool allow_nonfinite = false) {
  try {
    LoadOptions o;
    o.allow_nonfinite = allow_nonfinite;
    load_mesh(path, o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// Requires an InputError naming the file and containing `fragment`.
void require_error(const std::string& path, const std::string& fragment, bool allow_nonfinite = false) {
  const std::string msg = load_error(path, allow_nonfinite);
  INFO("path: " << path << "\nmessage: " << msg);
  REQUIRE(!msg.empty());
  CHECK(msg.rfind(path, 0) == 0);  // "FILE:LINE: ..." or "FILE: ..."
  CHECK(msg.find(fragment) != std::string::npos);
}

/// Requires the error to carry this line number.
void require_error_line(const std::string& path, std::int64_t line) {
  try {
    load_mesh(path);
  } catch (const InputError& e) {
    CHECK(e.file() == path);
    CHECK(e.line() == line);
    return;
  }
  FAIL("no InputError for " << path);
}

void check_triangle(const TriangleSoup& s, std::uint32_t t, Vec3f a, Vec3f b, Vec3f c) {
  INFO("triangle " << t);
  REQUIRE(t < s.size());
  CHECK(s.corner(t, 0) == a);
  CHECK(s.corner(t, 1) == b);
  CHECK(s.corner(t, 2) == c);
}

// The square-and-apex used by most small files: P0..P4.
const Vec3f P0{0, 0, 0}, P1{1, 0, 0}, P2{1, 1, 0}, P3{0, 1, 0}, P4{0, 0, 1};

// Little-endian binary builders.
void put_f32(std::string& s, float v) { s.append(reinterpret_cast<const char*>(&v), 4); }
void put_f64(std::string& s, double v) { s.append(reinterpret_cast<const char*>(&v), 8); }
void put_i32(std::string& s, std::int32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); }
void put_u8(std::string& s, std::uint8_t v) { s.push_back(static_cast<char>(v)); }
void put_f32_be(std::string& s, float v) {
  char b[4];
  std::memcpy(b, &v, 4);
  for (int i = 3; i >= 0; --i) s.push_back(b[i]);
}
void put_i32_be(std::string& s, std::int32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);
  for (int i = 3; i >= 0; --i) s.push_back(b[i]);
}

const std::string kObjPolygons =
    "# polygons, index forms, negative indices\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
    "vt 0 0\nvn 0 0 1\n"
    "f 1 2 3 4\n"                          // quad: t0 (0,1,2), t1 (0,2,3)
    "f 1/1 2/1 5/1\n"                      // t2 (0,1,4)
    "f 1//1 3//1 5//1\n"                   // t3 (0,2,4)
    "f 2/1/1 3/1/1 4/1/1 5/1/1 1/1/1\n"    // pentagon: t4 (1,2,3), t5 (1,3,4), t6 (1,4,0)
    "f -5 -4 -1\n";                        // t7 (0,1,4)

}  // namespace

// ---------------------------------------------------------------------------
// Formats and numbering

TEST_CASE("OBJ: polygons, index forms and negative indices keep formats.md numbering", "[load]") {
  const std::string path = write_file("polygons.obj", kObjPolygons);
  LoadReport r;
  const TriangleSoup s = load_mesh(path, {}, &r);
  REQUIRE(s.size() == 8);
  check_triangle(s, 0, P0, P1, P2);
  check_triangle(s, 1, P0, P2, P3);
  check_triangle(s, 2, P0, P1, P4);
  check_triangle(s, 3, P0, P2, P4);
  check_triangle(s, 4, P1, P2, P3);
  check_triangle(s, 5, P1, P3, P4);
  check_triangle(s, 6, P1, P4, P0);
  check_triangle(s, 7, P0, P1, P4);
  CHECK(r.format == "obj");
  CHECK(r.vertices == 5);
  CHECK(r.unreferenced_vertices == 0);
  CHECK(r.faces == 5);
  CHECK(r.triangles == 8);
  CHECK(r.degenerate == 0);
  CHECK(r.nonfinite_triangles == 0);
  REQUIRE(s.degenerate.size() == 8);
}

TEST_CASE("OBJ: negative indices are relative to the v lines read so far", "[load]") {
  const std::string path = write_file("relative.obj",
                                      "v 0 0 0\nv 1 0 0\nv 1 1 0\nf -3 -2 -1\n"
                                      "v 0 1 0\nv 0 0 1\nf -1 -2 -5\n");
  const TriangleSoup s = load_mesh(path);
  REQUIRE(s.size() == 2);
  check_triangle(s, 0, P0, P1, P2);
  check_triangle(s, 1, P4, P3, P0);
}

TEST_CASE("OBJ: repeated corners keep their fan triangles (OpenMesh would remove them)", "[load]") {
  // OpenMesh's OBJ reader turns "f 1 2 2 3" into "f 1 2 3" and drops "f 4 4 4".
  const std::string path = write_file("repeated.obj",
                                      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                      "f 1 2 2 3\nf 4 4 4\nf 1 2 3\n");
  LoadReport r;
  const TriangleSoup s = load_mesh(path, {}, &r);
  REQUIRE(s.size() == 4);
  check_triangle(s, 0, P0, P1, P1);
  check_triangle(s, 1, P0, P1, P2);
  check_triangle(s, 2, P3, P3, P3);
  check_triangle(s, 3, P0, P1, P2);
  CHECK(s.is_degenerate(0));
  CHECK(!s.is_degenerate(1));
  CHECK(s.is_degenerate(2));
  CHECK(!s.is_degenerate(3));
  CHECK(r.degenerate == 2);
  CHECK(r.faces == 3);
}

TEST_CASE("OBJ: non-manifold edges and duplicate faces are all kept", "[load]") {
  // Edge (1,2) is shared by four faces; the last face duplicates the first.
  const std::string path = write_file("nonmanifold.obj",
                                      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\n"
                                      "f 1 2 3\nf 1 2 4\nf 2 1 5\nf 1 2 3\n");
  const TriangleSoup s = load_mesh(path);
  REQUIRE(s.size() == 4);
  check_triangle(s, 0, P0, P1, Vec3f(0, 1, 0));
  check_triangle(s, 1, P0, P1, Vec3f(0, -1, 0));
  check_triangle(s, 2, P1, P0, P4);
  check_triangle(s, 3, P0, P1, Vec3f(0, 1, 0));
}

TEST_CASE("OBJ: collinear triangle is flagged degenerate, not dropped", "[load]") {
  const std::string path = write_file("collinear.obj", "v 0 0 0\nv 1 1 1\nv 3 3 3\nv 0 1 0\nf 1 2 3\nf 1 2 4\n");
  const TriangleSoup s = load_mesh(path);
  REQUIRE(s.size() == 2);
  CHECK(s.is_degenerate(0));
  CHECK(!s.is_degenerate(1));
}

TEST_CASE("PLY binary little-endian: float coords, extra properties, quads", "[load]") {
  std::string b =
      "ply\nformat binary_little_endian 1.0\ncomment like the dragon\n"
      "element vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\nproperty int flags\n"
      "element face 2\nproperty list uchar int vertex_indices\nproperty int flags\nend_header\n";
  for (const Vec3f& p : {P0, P1, P2, P3, P4}) {
    put_f32(b, p.x), put_f32(b, p.y), put_f32(b, p.z);
    put_f32(b, 0), put_f32(b, 0), put_f32(b, 1), put_i32(b, 7);
  }
  put_u8(b, 4), put_i32(b, 0), put_i32(b, 1), put_i32(b, 2), put_i32(b, 3), put_i32(b, 99);
  put_u8(b, 3), put_i32(b, 4), put_i32(b, 3), put_i32(b, 2), put_i32(b, 98);
  LoadReport r;
  const TriangleSoup s = load_mesh(write_file("bin.ply", b), {}, &r);
  REQUIRE(s.size() == 3);
  check_triangle(s, 0, P0, P1, P2);
  check_triangle(s, 1, P0, P2, P3);
  check_triangle(s, 2, P4, P3, P2);
  CHECK(r.format == "ply");
  CHECK(r.faces == 2);
  CHECK(r.vertices == 5);
}

TEST_CASE("PLY binary: double coords and 'list int int' faces", "[load]") {
  std::string b =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
      "property double z\nelement face 2\nproperty list int int vertex_indices\nend_header\n";
  const double third = 1.0 / 3.0;
  for (double x : {0.0, 1.0, third, 0.0}) put_f64(b, x), put_f64(b, x == 0.0 ? 0.0 : 1.0), put_f64(b, 2.0);
  put_i32(b, 3), put_i32(b, 0), put_i32(b, 1), put_i32(b, 2);
  put_i32(b, 3), put_i32(b, 2), put_i32(b, 1), put_i32(b, 3);
  const TriangleSoup s = load_mesh(write_file("double.ply", b));
  REQUIRE(s.size() == 2);
  check_triangle(s, 0, Vec3f(0, 0, 2), Vec3f(1, 1, 2), Vec3f(static_cast<float>(third), 1, 2));
  check_triangle(s, 1, Vec3f(static_cast<float>(third), 1, 2), Vec3f(1, 1, 2), Vec3f(0, 0, 2));
}

TEST_CASE("PLY binary big-endian", "[load]") {
  std::string b =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3f& p : {P1, P2, P4}) put_f32_be(b, p.x), put_f32_be(b, p.y), put_f32_be(b, p.z);
  put_u8(b, 3), put_i32_be(b, 2), put_i32_be(b, 0), put_i32_be(b, 1);
  const TriangleSoup s = load_mesh(write_file("be.ply", b));
  REQUIRE(s.size() == 1);
  check_triangle(s, 0, P4, P1, P2);
}

TEST_CASE("PLY ascii: quads, extra properties, unreferenced vertex", "[load]") {
  const std::string path = write_file("ascii.ply",
                                      "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
                                      "property float z\nproperty uchar red\nelement face 2\n"
                                      "property list uchar int vertex_indices\nend_header\n"
                                      "0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n0 0 1 5\n9 9 9 6\n"
                                      "4 3 2 1 0\n3 0 1 4\n");
  LoadReport r;
  const TriangleSoup s = load_mesh(path, {}, &r);
  REQUIRE(s.size() == 3);
  check_triangle(s, 0, P3, P2, P1);
  check_triangle(s, 1, P3, P1, P0);
  check_triangle(s, 2, P0, P1, P4);
  CHECK(r.vertices == 6);
  CHECK(r.unreferenced_vertices == 1);
}

TEST_CASE("OFF: quads, comments, counts on the OFF line, face colors", "[load]") {
  const std::string path = write_file("quads.off",
                                      "OFF 5 3 0\n# a comment\n0 0 0\n1 0 0 # another\n1 1 0\n0 1 0\n0 0 1\n"
                                      "4 0 1 2 3\n3 4 0 1 255 0 0\n5 0 1 2 3 4\n");
  LoadReport r;
  const TriangleSoup s = load_mesh(path, {}, &r);
  REQUIRE(s.size() == 6);
  check_triangle(s, 0, P0, P1, P2);
  check_triangle(s, 1, P0, P2, P3);
  check_triangle(s, 2, P4, P0, P1);
  check_triangle(s, 3, P0, P1, P2);
  check_triangle(s, 4, P0, P2, P3);
  check_triangle(s, 5, P0, P3, P4);
  CHECK(r.format == "off");
  CHECK(r.faces == 3);
}

namespace {
std::string ascii_stl(const std::vector<std::array<Vec3f, 3>>& facets) {
  std::string s = "solid test\n";
  for (const auto& f : facets) {
    s += "  facet normal 0 0 1\n    outer loop\n";
    for (const Vec3f& p : f)
      s += "      vertex " + std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
    s += "    endloop\n  endfacet\n";
  }
  return s + "endsolid test\n";
}
std::string binary_stl(const std::vector<std::array<Vec3f, 3>>& facets) {
  std::string s(80, ' ');
  put_i32(s, static_cast<std::int32_t>(facets.size()));
  for (const auto& f : facets) {
    put_f32(s, 0), put_f32(s, 0), put_f32(s, 1);
    for (const Vec3f& p : f) put_f32(s, p.x), put_f32(s, p.y), put_f32(s, p.z);
    s.append(2, '\0');
  }
  return s;
}
// Facet 1 repeats a corner: OpenMesh's STL reader drops it, we keep it.
const std::vector<std::array<Vec3f, 3>> kFacets = {
    {P0, P1, P2}, {P2, P2, P3}, {P0, P2, P3}, {P4, P0, P1}};
}  // namespace

TEST_CASE("STL ascii and binary: every facet in order, degenerate ones too", "[load]") {
  for (const std::string& path : {write_file("facets.stl", ascii_stl(kFacets)), write_file("facets_bin.stl", binary_stl(kFacets))}) {
    INFO(path);
    LoadReport r;
    const TriangleSoup s = load_mesh(path, {}, &r);
    REQUIRE(s.size() == 4);
    for (std::uint32_t t = 0; t < 4; ++t) check_triangle(s, t, kFacets[t][0], kFacets[t][1], kFacets[t][2]);
    CHECK(s.is_degenerate(1));
    CHECK(r.degenerate == 1);
    CHECK(r.format == "stl");
    CHECK(r.vertices == 5);  // corners merged
  }
}

TEST_CASE("Regression: an ascii STL solid named 'outer' (OpenMesh starts a facet there)", "[load]") {
  std::string text = ascii_stl(kFacets);
  text.replace(0, text.find('\n'), "solid outer_shell");
  text.replace(text.rfind("endsolid"), std::string::npos, "endsolid outer_shell\n");
  const TriangleSoup s = load_mesh(write_file("outer.stl", text));
  REQUIRE(s.size() == 4);
  for (std::uint32_t t = 0; t < 4; ++t) check_triangle(s, t, kFacets[t][0], kFacets[t][1], kFacets[t][2]);
}

TEST_CASE("Regression: OBJ mtllib is not opened (OpenMesh would read gigabytes of /dev/zero)", "[load]") {
  // The material library is a FIFO with no writer: opening it would block the
  // load forever (CTest's timeout then fails the test), so finishing at all
  // shows it was never opened. No timing is asserted.
  const std::string fifo = bsprt::test::temp_path("never_opened.mtl");
  std::filesystem::remove(fifo);
  REQUIRE(mkfifo(fifo.c_str(), 0600) == 0);
  LoadReport r;
  const TriangleSoup s = load_mesh(
      write_file("mtllib.obj", "mtllib " + fifo + "\nmtllib /dev/zero\nusemtl x\n" + kObjPolygons), {}, &r);
  CHECK(s.size() == 8);
  std::filesystem::remove(fifo);
}

TEST_CASE("OBJ with a UTF-8 byte order mark keeps its first vertex", "[load]") {
  const TriangleSoup s = load_mesh(write_file("bom.obj", std::string("\xEF\xBB\xBF") + kObjPolygons.substr(kObjPolygons.find("\nv ") + 1)));
  REQUIRE(s.size() == 8);
  check_triangle(s, 0, P0, P1, P2);
}

TEST_CASE("Extension is case-insensitive", "[load]") {
  const TriangleSoup s = load_mesh(write_file("upper.OBJ", kObjPolygons));
  CHECK(s.size() == 8);
}

// ---------------------------------------------------------------------------
// Errors

TEST_CASE("Errors: extension, missing, empty, no triangles", "[load][errors]") {
  require_error(write_file("mesh.xyz", kObjPolygons), "unknown mesh file extension");
  require_error(test::temp_path("does_not_exist.obj"), "no such file");
  require_error(write_file("empty.obj", ""), "empty");
  require_error(write_file("empty.ply", ""), "empty");
  require_error(write_file("empty.stl", ""), "empty");
  require_error(write_file("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"), "no triangles");
  require_error(write_file("nofaces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n"), "no triangles");
  require_error(write_file("nofaces.stl", "solid x\nendsolid x\n"), "no triangles");
}

TEST_CASE("Errors: OBJ indices", "[load][errors]") {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  require_error(write_file("range.obj", v + "f 1 2 4\n"), "vertex 4");
  require_error_line(write_file("range_line.obj", v + "f 1 2 3\nf 1 2 4\n"), 5);
  require_error(write_file("zero.obj", v + "f 0 1 2\n"), "index 0");
  require_error(write_file("before.obj", v + "f -1 -2 -4\n"), "before vertex 1");
  require_error(write_file("garbage.obj", v + "f 1 2 x\n"), "integer index");
  require_error(write_file("two.obj", v + "f 1 2\n"), "needs at least 3");
}

TEST_CASE("Errors: OBJ vertices", "[load][errors]") {
  require_error(write_file("short_v.obj", "v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "needs 3");
  require_error(write_file("word_v.obj", "v 0 zero 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "not a number");
}

TEST_CASE("Non-finite OBJ vertices: error when used, flagged with allow_nonfinite", "[load][nonfinite]") {
  const std::string used = write_file("nan_used.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 1 4 3\n");
  require_error(used, "not finite");
  require_error_line(used, 2);
  LoadOptions allow;
  allow.allow_nonfinite = true;
  LoadReport r;
  const TriangleSoup s = load_mesh(used, allow, &r);
  REQUIRE(s.size() == 2);
  CHECK(std::isnan(s.corner(0, 1).x));
  CHECK(s.corner(1, 1) == Vec3f(1, 1, 0));  // later vertices not shifted
  CHECK(s.is_degenerate(0));
  CHECK(!s.is_degenerate(1));
  CHECK(r.nonfinite_triangles == 1);
  CHECK(r.degenerate == 1);
  // An unused non-finite vertex (any spelling) is harmless.
  const TriangleSoup u = load_mesh(write_file("nan_unused.obj",
                                              "v 1.#IND -1.#INF inf\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 2 3 4\n"));
  REQUIRE(u.size() == 1);
  check_triangle(u, 0, P0, P1, Vec3f(0, 1, 0));
}

TEST_CASE("Errors: PLY counts that lie and truncation", "[load][errors]") {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  require_error(write_file("few_v.ply", head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n"), "face vertex count");
  require_error(write_file("few_f.ply", head + "0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n"), "file ends inside face");
  require_error(write_file("more_f.ply", head + "0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 0 2 1\n3 1 2 3\n"),
                "counts lie");
  require_error(write_file("range.ply", head + "0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 0 2 4\n"), "not in 0..3");
  require_error_line(write_file("range_line.ply", head + "0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 0 2 4\n"), 15);
  require_error(write_file("neg.ply", head + "0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 0 2 -1\n"), "not in 0..3");
  require_error(write_file("two.ply", head + "0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n2 0 2\n"), ">= 3");
  require_error(write_file("word.ply", head + "0 0 0\n1 zero 0\n0 1 0\n1 1 0\n3 0 1 2\n3 0 2 1\n"), "not a number");
  require_error(write_file("noend.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"), "end_header");
  require_error(write_file("notply.ply", "hello\n"), "not a PLY file");
  // Regression: OpenMesh 9.0's header parser loops forever on a bad version.
  require_error(write_file("version.ply", "ply\nformat ascii f.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                          "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                          "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                "1.0");
  // Comments and odd spacing in the header are fine (OpenMesh gets a rebuilt header).
  const TriangleSoup s = load_mesh(write_file("spaced.ply", "ply\ncomment hi there\nformat  ascii 1.0\nelement vertex 3\n"
                                                             "property float x\nproperty float y\nproperty  float z\n"
                                                             "obj_info x\nelement face 1\nproperty list uchar int vertex_indices\n"
                                                             "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
  CHECK(s.size() == 1);
}

namespace {
std::string binary_ply_quad() {
  std::string b =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3f& p : {P0, P1, P2, P3}) put_f32(b, p.x), put_f32(b, p.y), put_f32(b, p.z);
  put_u8(b, 4), put_i32(b, 0), put_i32(b, 1), put_i32(b, 2), put_i32(b, 3);
  return b;
}
}  // namespace

TEST_CASE("Errors: binary PLY truncated, extra bytes, bad index", "[load][errors]") {
  const std::string good = binary_ply_quad();
  REQUIRE(load_mesh(write_file("quad_bin.ply", good)).size() == 2);
  require_error(write_file("trunc_face.ply", good.substr(0, good.size() - 3)), "truncated");
  require_error(write_file("trunc_vertex.ply", good.substr(0, good.size() - 30)), "truncated");
  require_error(write_file("extra.ply", good + std::string(17, '\x01')), "counts lie");
  std::string bad = good;
  const std::int32_t seven = 7;
  std::memcpy(&bad[bad.size() - 4], &seven, 4);
  require_error(write_file("bad_index.ply", bad), "vertex index 7");
}

TEST_CASE("Non-finite PLY coordinates: ascii and binary", "[load][nonfinite]") {
  const std::string ascii = write_file("nan_ascii.ply",
                                       "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                       "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
                                       "end_header\n0 0 0\n1 0 0\n0 nan 0\n1 1 0\n3 0 1 2\n3 0 1 3\n");
  require_error(ascii, "not finite");
  require_error_line(ascii, 12);
  std::string b = binary_ply_quad();
  const float inf = std::numeric_limits<float>::infinity();
  const std::size_t p1x = b.find("end_header\n") + 11 + 12;
  std::memcpy(&b[p1x], &inf, 4);
  const std::string binary = write_file("inf_bin.ply", b);
  require_error(binary, "not finite");
  LoadOptions allow;
  allow.allow_nonfinite = true;
  for (const std::string& path : {ascii, binary}) {
    INFO(path);
    LoadReport r;
    const TriangleSoup s = load_mesh(path, allow, &r);
    REQUIRE(s.size() == 2);
    CHECK(r.nonfinite_triangles >= 1);
    CHECK(s.is_degenerate(0));
  }
  const TriangleSoup s = load_mesh(ascii, allow);
  CHECK(std::isnan(s.corner(0, 2).y));
  check_triangle(s, 1, P0, P1, P2);  // later vertices intact
}

TEST_CASE("Errors: OFF counts that lie, bad indices", "[load][errors]") {
  const std::string v = "0 0 0\n1 0 0\n0 1 0\n1 1 0\n";
  require_error(write_file("few_f.off", "OFF\n4 3 0\n" + v + "3 0 1 2\n3 1 3 2\n"), "file ends after 2 of the 3 faces");
  require_error(write_file("few_v.off", "OFF\n5 1 0\n" + v + "3 0 1 2\n"), "file ends after 0 of the 1 faces");
  require_error(write_file("more_f.off", "OFF\n4 1 0\n" + v + "3 0 1 2\n3 1 3 2\n"), "counts lie");
  require_error(write_file("range.off", "OFF\n4 1 0\n" + v + "3 0 1 4\n"), "not in 0..3");
  require_error(write_file("notoff.off", "FOO\n4 1 0\n" + v + "3 0 1 2\n"), "not an OFF file");
  require_error(write_file("nan.off", "OFF\n4 1 0\n0 0 0\ninf 0 0\n0 1 0\n1 1 0\n3 0 1 2\n"), "not finite");
}

TEST_CASE("Errors: STL size, truncation, non-finite", "[load][errors]") {
  const std::string bin = binary_stl(kFacets);
  require_error(write_file("short.stl", bin.substr(0, bin.size() - 10)), "bytes");
  require_error(write_file("long.stl", bin + "xx"), "bytes");
  const std::string ascii = ascii_stl(kFacets);
  require_error(write_file("trunc.stl", ascii.substr(0, ascii.find("endfacet"))), "truncated");
  require_error(write_file("fourv.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                        "vertex 0 1 0\nvertex 1 1 1\nendloop\nendfacet\nendsolid x\n"),
                "exactly 3 vertices");
  const std::string nan = write_file("nan.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                                                "vertex nan 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid x\n");
  require_error(nan, "non-finite");
  LoadOptions allow;
  allow.allow_nonfinite = true;
  LoadReport r;
  const TriangleSoup s = load_mesh(nan, allow, &r);
  REQUIRE(s.size() == 1);
  CHECK(r.nonfinite_triangles == 1);
  CHECK(s.is_degenerate(0));
}

// ---------------------------------------------------------------------------
// Shared scenes (shared/scenes/SOURCES.md)

TEST_CASE("Shared scenes load with the triangle counts of SOURCES.md", "[load][scenes]") {
  struct Expect {
    const char* file;
    std::size_t triangles, faces, vertices, unreferenced;
  };
  const Expect table[] = {
      {"stanford-bunny.obj", 69451, 69451, 35947, 1113},
      {"stanford-dragon-100k.ply", 100000, 100000, 50000, 0},
      {"happy-buddha-res4.ply", 15536, 15536, 7108, 6},
      {"armadillo-86k.obj", 86482, 86482, 43243, 0},
      {"utah-teapot.obj", 6320, 6320, 3644, 0},
      {"suzanne.obj", 968, 500, 507, 0},
      {"cube.obj", 12, 12, 8, 0},
      {"cornell_box.obj", 34, 17, 76, 8},
      {"stiff_sliver_tet.ply", 4, 4, 5009, 5005},
      {"stiff_degenerated.obj", 24, 24, 7, 0},
      {"stiff_planexy.off", 32, 32, 25, 0},
      {"stiff_cube_with_fold.ply", 48, 48, 26, 0},
      {"stiff_two-boxes-bad-self-union.ply", 708, 708, 486, 0},
      {"stiff_truck.obj", 4770, 4770, 2956, 0},
  };
  for (const Expect& e : table) {
    INFO(e.file);
    LoadReport r;
    const TriangleSoup s = load_mesh(test::scene_path(e.file), {}, &r);
    CHECK(s.size() == e.triangles);
    CHECK(r.triangles == e.triangles);
    CHECK(r.faces == e.faces);
    CHECK(r.vertices == e.vertices);
    CHECK(r.unreferenced_vertices == e.unreferenced);
    CHECK(r.nonfinite_triangles == 0);
    CHECK(s.degenerate.size() == s.size());
    CHECK(r.degenerate == 0);  // SOURCES.md: no zero-area triangles
  }
}

TEST_CASE("Shared stiff_test-nan.obj: error by default, 36 triangles with allow_nonfinite", "[load][scenes]") {
  const std::string path = test::scene_path("stiff_test-nan.obj");
  require_error(path, "not finite");
  LoadOptions allow;
  allow.allow_nonfinite = true;
  LoadReport r;
  const TriangleSoup s = load_mesh(path, allow, &r);
  CHECK(s.size() == 36);
  CHECK(r.faces == 18);
  CHECK(r.vertices == 76);
  CHECK(r.unreferenced_vertices == 4);  // the front wall's face is commented out
  CHECK(r.nonfinite_triangles == 2);    // "f 1 2 3 4" uses the four non-finite vertices
  CHECK(r.degenerate == 2);
  // The light ("f -4 -3 -2 -1" after 16 v lines) is not shifted by the NaN lines.
  check_triangle(s, 6, Vec3f(343.0f, 548.0f, 227.0f), Vec3f(343.0f, 548.0f, 332.0f), Vec3f(213.0f, 548.0f, 332.0f));
}

TEST_CASE("Bunny bounds match SOURCES.md's scale", "[load][scenes]") {
  const TriangleSoup s = load_mesh(test::scene_path("stanford-bunny.obj"));
  const Box3f b = s.bounds();
  CHECK(b.diagonal().x == Approx(0.16).margin(0.01));
  CHECK(b.diagonal().y == Approx(0.15).margin(0.01));
  CHECK(b.diagonal().z == Approx(0.12).margin(0.01));
}

// ---------------------------------------------------------------------------
// Exact degeneracy and TriangleSoup helpers

TEST_CASE("is_degenerate_exact decides collinearity exactly", "[degenerate]") {
  CHECK(is_degenerate_exact(P0, P1, P1));
  CHECK(is_degenerate_exact(P0, P0, P0));
  CHECK(is_degenerate_exact(P0, Vec3f(1, 1, 1), Vec3f(3, 3, 3)));
  CHECK(!is_degenerate_exact(P0, P1, P3));
  // One ulp off the line: a tiny but real triangle.
  const float off = std::nextafter(3.0f, 4.0f);
  CHECK(!is_degenerate_exact(P0, Vec3f(1, 1, 1), Vec3f(3, 3, off)));
  // Far from the origin, where a naive float cross product rounds to zero.
  const float big = 16777216.0f;  // 2^24
  CHECK(!is_degenerate_exact(Vec3f(big, big, big), Vec3f(big + 2, big, big), Vec3f(big, big + 2, big)));
  CHECK(is_degenerate_exact(Vec3f(big, big, big), Vec3f(big + 2, big + 2, big + 2), Vec3f(big + 4, big + 4, big + 4)));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  CHECK(is_degenerate_exact(Vec3f(nan, 0, 0), P1, P3));
  CHECK(is_degenerate_exact(P0, Vec3f(0, std::numeric_limits<float>::infinity(), 0), P3));
}

TEST_CASE("TriangleSoup bounds, degenerate_count and append", "[soup]") {
  TriangleSoup a;
  a.vertices = {P0, P1, P3, Vec3f(5, 5, 5), Vec3f(-9, -9, -9)};
  a.triangles = {{0, 1, 2}, {0, 3, 3}};
  REQUIRE(classify_degenerate(a) == 1);
  CHECK(a.degenerate_count() == 1);
  const Box3f box = a.bounds();  // ignores the degenerate triangle and vertex 4
  CHECK(box.lo == P0);
  CHECK(box.hi == Vec3f(1, 1, 0));

  TriangleSoup b;
  b.vertices = {P4, P1, P2};
  b.triangles = {{0, 1, 2}};
  append(a, b);
  REQUIRE(a.size() == 3);
  CHECK(a.vertices.size() == 8);
  check_triangle(a, 2, P4, P1, P2);
  REQUIRE(a.degenerate.size() == 3);
  CHECK(a.degenerate_count() == 1);
  CHECK(a.bounds().hi == Vec3f(1, 1, 1));
}

// Found by an adversarial review of the readers (2026-12-07); each was a hang,
// a silent loss or a misleading error.
TEST_CASE("PLY: an element of records with no properties is an error, not a 2^31-step loop", "[load][regression]") {
  std::string b =
      "ply\nformat binary_little_endian 1.0\nelement junk 2147483647\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3f& p : {P0, P1, P2}) put_f32(b, p.x), put_f32(b, p.y), put_f32(b, p.z);
  put_u8(b, 3), put_i32(b, 0), put_i32(b, 1), put_i32(b, 2);
  require_error(write_file("noprops.ply", b), ":3: PLY element 'junk' declares 2147483647 records but no properties");
}

TEST_CASE("PLY binary: a face past the declared count is an error even when its bytes are whitespace",
          "[load][regression]") {
  const auto file = [](int declared) {
    std::string b = "ply\nformat binary_little_endian 1.0\nelement vertex 14\nproperty float x\nproperty float y\n"
                    "property float z\nelement face " + std::to_string(declared) +
                    "\nproperty list uchar uchar vertex_indices\nend_header\n";
    for (int v = 0; v < 14; ++v) put_f32(b, float(v)), put_f32(b, float(v * v % 7)), put_f32(b, float(v % 3));
    for (int k : {3, 0, 1, 2}) put_u8(b, std::uint8_t(k));
    for (int k : {9, 10, 11, 12, 13, 9, 10, 11, 12, 13}) put_u8(b, std::uint8_t(k));  // 9 corners: tab, LF, VT, FF, CR
    return b;
  };
  require_error(write_file("ws_tail.ply", file(1)), "10 bytes after the last element");
  CHECK(load_mesh(write_file("ws_tail_ok.ply", file(2))).size() == 1 + 7);  // the 9-gon is 7 triangles
}

TEST_CASE("PLY binary: property types OpenMesh cannot convert are skipped or named", "[load][regression]") {
  // A vertex property 's' (a texture coordinate to OpenMesh) of type short,
  // list counts of type int32 (which OpenMesh's header parser refuses) and
  // ushort indices: OpenMesh printed to std::cerr and misread the rest.
  std::string b =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nproperty short s\nproperty uchar red\nelement face 2\n"
      "property list int32 ushort vertex_indices\nproperty double red\nend_header\n";
  for (const Vec3f& p : {P0, P1, P2, P3}) put_f32(b, p.x), put_f32(b, p.y), put_f32(b, p.z), put_u8(b, 7), put_u8(b, 0), put_u8(b, 200);
  const auto put_u16 = [&b](int v) { put_u8(b, std::uint8_t(v & 255)), put_u8(b, std::uint8_t(v >> 8)); };
  put_i32(b, 3), put_u16(0), put_u16(1), put_u16(2), put_f64(b, 0.5);
  put_i32(b, 3), put_u16(0), put_u16(2), put_u16(3), put_f64(b, 0.25);
  const TriangleSoup s = load_mesh(write_file("types.ply", b));
  REQUIRE(s.size() == 2);
  check_triangle(s, 0, P0, P1, P2);
  check_triangle(s, 1, P0, P2, P3);
  std::string c =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty int x\nproperty int y\nproperty int z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (int v : {0, 0, 0, 1, 0, 0, 0, 1, 0}) put_i32(c, v);
  put_u8(c, 3), put_i32(c, 0), put_i32(c, 1), put_i32(c, 2);
  require_error(write_file("intcoords.ply", c), "binary PLY vertex coordinate 'x' of type int is not supported");
}

TEST_CASE("OBJ: a CR joining statements and a word after v coordinates are errors, colors and 1-value vt load",
          "[load][regression]") {
  require_error(write_file("mixcr.obj", "v 0 0 0\nv 1 0 0\rv 9 9 9\nv 0 1 0\nf -3 -2 -1\n"),
                ":2: carriage return inside a line");
  require_error(write_file("cr_only.obj", "v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r"), ":1: carriage return inside a line");
  require_error(write_file("vword.obj", "v 0 0 0 v\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), ":1: vertex 1: 'v' after the coordinates");
  require_error(write_file("cr_comment_joins.obj", "# c\rv 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r"),
                ":1: carriage return inside a line");
  // Valid files that must keep loading: CRs in a comment, CR CR LF line ends,
  // and v lines with 5 or 8 values (exporters add weights and colours).
  for (const char* text : {"# a comment\r with a CR\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
                           "v 0 0 0\r\r\nv 1 0 0\r\r\nv 0 1 0\r\r\nf 1 2 3\r\r\n",
                           "v 0 0 0 1 2\nv 1 0 0 1 2\nv 0 1 0 1 1 0 0 1\nf 1 2 3\n"}) {
    INFO(text);
    CHECK(load_mesh(write_file("cr_ok.obj", text)).size() == 1);
  }
  const TriangleSoup s = load_mesh(write_file(
      "colors_vt.obj", "v 0 0 0 1 0 0\nv 1 0 0 0.5 0.5 0.5 1\nv 0 1 0 nan 0 0\nv 0 0 1 2\nvt 0.5\nvt nan 0\n"
                       "f 1/1 2/2 3/1\nf 1 3 4\n"));
  REQUIRE(s.size() == 2);
  check_triangle(s, 0, P0, P1, P3);
  check_triangle(s, 1, P0, P3, P4);
}

TEST_CASE("STL: corners closer than FLT_MIN stay apart, as in the other formats", "[load][regression]") {
  const Vec3f tiny{1e-39f, 0, 0};
  const std::vector<std::array<Vec3f, 3>> facets = {{P0, P1, P3}, {tiny, P1, P3}};
  const TriangleSoup s = load_mesh(write_file("tiny_bin.stl", binary_stl(facets)));
  REQUIRE(s.size() == 2);
  CHECK(s.corner(1, 0).x == 1e-39f);
  CHECK(!s.is_degenerate(1));
  CHECK(s.degenerate_count() == 0);
}

TEST_CASE("STL and OFF: a blank line in a loop, a binary 'solid' header and face colors on some faces", "[load][regression]") {
  // A blank line inside `outer loop` is legal ascii STL; OpenMesh took it for a vertex.
  const TriangleSoup a = load_mesh(write_file(
      "blank.stl", "solid s\nfacet normal 0 0 1\nouter loop\n\nvertex 0 0 0\nvertex 1 0 0\n\nvertex 0 1 0\nendloop\n"
                   "endfacet\nendsolid s\n"));
  REQUIRE(a.size() == 1);
  check_triangle(a, 0, P0, P1, P3);
  // A binary file whose header starts with "solid" and whose count lies gets the binary message.
  std::string b = binary_stl({{P0, P1, P3}, {P0, P3, P4}});
  b.replace(0, 5, "solid");
  b[80] = 3;
  require_error(write_file("solid_header.stl", b), "binary STL: header declares 3 triangles");
  // OFF face colors are optional per face, with or without a C header.
  for (const std::string head : {"COFF\n4 2 0\n0 0 0 1 0 0 1\n1 0 0 1 0 0 1\n0 1 0 1 0 0 1\n0 0 1 1 0 0 1\n",
                                 "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"}) {
    const TriangleSoup o = load_mesh(write_file("part_colors.off", head + "3 0 1 2 1 0 0\n3 0 2 3\n"));
    INFO(head);
    REQUIRE(o.size() == 2);
  }
}
