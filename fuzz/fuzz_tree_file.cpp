// libFuzzer harness for the tree-file readers (kd and BSP, builder/tree_file.h,
// kd_file.h, bsp_file.h, bsp_flat_io.h): any bytes, read as a tree file for a
// small fixed scene through make_tracer(--tree), must either load or throw
// InputError; a tree that loads must trace rays without crashing.
// So that mutations reach the section parsers, the harness patches the
// header's scene fingerprint, triangle count and CRC-32 to match (inputs
// shorter than the 40-byte header are read as they are).
#include <unistd.h>

#include <span>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "builder/accel_factory.h"
#include "builder/bsp/bsp_build.h"
#include "builder/bsp/bsp_file.h"
#include "builder/kd/kd_build.h"
#include "builder/kd/kd_file.h"
#include "builder/tree_file.h"
#include "geometry/scenes/default_scene.h"
#include "bsprt/error.h"
#include "geometry/scenes/ray_gen.h"

namespace {

/// The fixed scene every input is read against (80-triangle icosphere).
const bsprt::TriangleSoup& scene() {
  static const bsprt::TriangleSoup s = bsprt::make_icosphere({0.25f, 0.5f, -0.125f}, 1.0f, 1);
  return s;
}

void put_u64(std::vector<std::uint8_t>& b, std::size_t at, std::uint64_t v) { std::memcpy(b.data() + at, &v, 8); }

std::vector<std::uint8_t> patched(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> b(data, data + size);
  if (b.size() < 40) return b;
  put_u64(b, 16, bsprt::scene_fingerprint(scene()));
  put_u64(b, 24, scene().size());
  std::uint32_t version;
  std::memcpy(&version, b.data() + 8, 4);
  const std::uint32_t c = bsprt::tree_file_crc(std::as_bytes(std::span(b)), version);
  std::memcpy(b.data() + 36, &c, 4);
  return b;
}

void try_accel(const std::string& accel, const std::string& path) {
  bsprt::AccelOptions o;
  o.tree_path = path;
  o.threads = 1;
  std::unique_ptr<bsprt::Accelerator> t;
  try {
    t = bsprt::make_tracer(accel, scene(), o);
  } catch (const bsprt::InputError&) {
    return;
  }
  static const std::vector<bsprt::Ray> rays = bsprt::vertex_rays(scene(), 32, 5);
  for (const bsprt::Ray& r : rays) (void)t->trace(r);
}

/// With BSPRT_FUZZ_WRITE_SEEDS=dir, writes a valid kd and BSP tree file of the
/// fixed scene there (how fuzz/corpus/tree_file/ was made).
void write_seeds(const std::string& dir) {
  bsprt::write_kd_tree(dir + "/kd.tree", bsprt::build_kd(scene()), scene());
  bsprt::write_bsp_file(dir + "/bsp.tree", scene(), bsprt::build_bsp(scene()));
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* dir = std::getenv("BSPRT_FUZZ_WRITE_SEEDS")) write_seeds(dir);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = "/tmp/bsprt_fuzz_tree_" + std::to_string(getpid());
  const std::vector<std::uint8_t> bytes = patched(data, size);
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  }
  try_accel("kd", path);
  try_accel("kd-float", path);
  try_accel("bsp", path);
  try_accel("bsp-float", path);
  try_accel("bsp-top", path);
  try_accel("bsp-top-float", path);
  std::remove(path.c_str());
  return 0;
}
