// `.rays` and `.hits` files (geometry/ray_io.h, shared/formats.md): round trips
// and every malformed file we can think of, each throwing InputError that
// names the file.
#include <catch2/catch.hpp>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "bsprt/error.h"
#include "bsprt/io.h"
#include "test_util.h"

using namespace bsprt;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

std::vector<Ray> sample_rays(std::size_t n) {
  std::vector<Ray> rays(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float f = float(i);
    rays[i].org = {f, -f, 0.5f * f};
    rays[i].dir = {1.0f, f * 1e-3f, -2.0f};
    rays[i].tnear = 1e-4f * f;
    rays[i].tfar = i % 3 == 0 ? kInf : 100.0f + f;
  }
  if (n > 1) rays[1].org.x = std::numeric_limits<float>::quiet_NaN();  // kept as is
  return rays;
}

/// Writes raw bytes to `path`.
void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

std::string header(const char* magic, std::uint32_t version, std::uint64_t n) {
  std::string h(16, '\0');
  std::memcpy(h.data(), magic, 4);
  std::memcpy(h.data() + 4, &version, 4);
  std::memcpy(h.data() + 8, &n, 8);
  return h;
}

/// Runs `f`, expects an InputError naming `path` whose message contains `part`.
template <typename F>
void expect_input_error(F f, const std::string& path, const std::string& part) {
  try {
    f();
    FAIL("no InputError for " << path);
  } catch (const InputError& e) {
    INFO(e.what());
    CHECK(e.file() == path);
    CHECK(std::string(e.what()).find(path) != std::string::npos);
    CHECK(std::string(e.what()).find(part) != std::string::npos);
  }
}

}  // namespace

TEST_CASE("ray_io: rays and hits round trip bit for bit", "[ray_io]") {
  const std::string rp = test::temp_path("round.rays"), hp = test::temp_path("round.hits");
  for (std::size_t n : {std::size_t(0), std::size_t(1), std::size_t(1000)}) {
    const std::vector<Ray> rays = sample_rays(n);
    write_rays(rp, rays);
    CHECK(std::filesystem::file_size(rp) == 16 + 32 * n);
    const std::vector<Ray> back = read_rays(rp);
    REQUIRE(back.size() == n);
    CHECK((n == 0 || std::memcmp(back.data(), rays.data(), n * sizeof(Ray)) == 0));

    std::vector<Hit> hits(n);
    for (std::size_t i = 0; i < n; ++i)
      if (i % 2) hits[i] = Hit{float(i), std::uint32_t(i * 7), 0.25f, 0.5f};
    write_hits(hp, hits);
    CHECK(std::filesystem::file_size(hp) == 16 + 16 * n);
    const std::vector<Hit> hback = read_hits(hp);
    REQUIRE(hback.size() == n);
    CHECK((n == 0 || std::memcmp(hback.data(), hits.data(), n * sizeof(Hit)) == 0));
  }
}

TEST_CASE("ray_io: the header is little-endian as documented", "[ray_io]") {
  const std::string p = test::temp_path("layout.hits");
  write_hits(p, std::vector<Hit>{Hit{}});
  std::ifstream in(p, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  REQUIRE(bytes.size() == 32);
  CHECK(bytes.substr(0, 16) == header("HITS", 1, 1));
  std::uint32_t prim;
  std::memcpy(&prim, bytes.data() + 20, 4);
  CHECK(prim == 0xFFFFFFFFu);
}

TEST_CASE("ray_io: malformed files throw InputError naming the file", "[ray_io]") {
  const std::string p = test::temp_path("bad.rays"), h = test::temp_path("bad.hits");
  const std::string record(32, '\0'), hrec(16, '\0');

  write_bytes(p, header("RAYZ", 1, 1) + record);
  expect_input_error([&] { read_rays(p); }, p, "bad magic 'RAYZ'");
  write_bytes(p, header("HITS", 1, 1) + hrec);  // a hits file read as rays
  expect_input_error([&] { read_rays(p); }, p, "expected 'RAYS'");
  write_bytes(p, header("RAYS", 2, 1) + record);
  expect_input_error([&] { read_rays(p); }, p, "version 2");
  write_bytes(p, header("RAYS", 1, 2) + record);
  expect_input_error([&] { read_rays(p); }, p, "expected 80 bytes for 2 rays, file has 48");
  write_bytes(p, header("RAYS", 1, 1) + record + "x");
  expect_input_error([&] { read_rays(p); }, p, "expected 48 bytes for 1 rays, file has 49");
  write_bytes(p, "");
  expect_input_error([&] { read_rays(p); }, p, "empty");
  write_bytes(p, "RAYS\1\0");
  expect_input_error([&] { read_rays(p); }, p, "truncated header");
  // Garbage N: must not try to allocate.
  write_bytes(p, header("RAYS", 1, std::uint64_t(1) << 62) + record);
  expect_input_error([&] { read_rays(p); }, p, "file has 48");
  write_bytes(p, header("RAYS", 1, ~std::uint64_t(0)) + record);
  expect_input_error([&] { read_rays(p); }, p, "more than 2^64");

  write_bytes(h, header("HITS", 1, 3) + hrec);
  expect_input_error([&] { read_hits(h); }, h, "expected 64 bytes for 3 hits, file has 32");
  write_bytes(h, header("HITS", 7, 1) + hrec);
  expect_input_error([&] { read_hits(h); }, h, "version 7");

  const std::string missing = test::temp_path("does_not_exist.rays");
  std::filesystem::remove(missing);
  expect_input_error([&] { read_rays(missing); }, missing, "cannot open");
  expect_input_error([&] { read_hits(missing); }, missing, "cannot open");
  const std::string dir = test::temp_path("a_directory.rays");
  std::filesystem::create_directories(dir);
  expect_input_error([&] { read_rays(dir); }, dir, "directory");
  expect_input_error([&] { write_rays(dir, sample_rays(1)); }, dir, "cannot open");
}

TEST_CASE("ray_io: a truncated large file reports sizes", "[ray_io]") {
  const std::string p = test::temp_path("big.rays");
  write_rays(p, sample_rays(100000));
  std::filesystem::resize_file(p, 3200000);
  expect_input_error([&] { read_rays(p); }, p, "expected 3200016 bytes for 100000 rays, file has 3200000");
}

// Found by an adversarial review of the readers (2026-12-07): write_hits wrote
// records that read_hits refuses (t = NaN with a triangle).
TEST_CASE("ray_io: write_hits refuses a record read_hits would refuse, and writes nothing", "[ray_io][regression]") {
  const std::string path = test::temp_path("bad_record.hits");
  std::remove(path.c_str());
  std::vector<Hit> hits(2);
  hits[0] = Hit{1.5f, 3, 0.25f, 0.25f};
  hits[1] = Hit{std::numeric_limits<float>::quiet_NaN(), 2, 0.0f, 0.0f};
  CHECK_THROWS_WITH(write_hits(path, hits), Catch::Contains("hit record 1 is"));
  CHECK(!std::ifstream(path).good());
  hits.pop_back();
  write_hits(path, hits);
  CHECK(read_hits(path).size() == 1);
}
