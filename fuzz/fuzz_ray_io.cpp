// libFuzzer harness for the .rays and .hits readers: any bytes must either
// read back as whole records or throw InputError.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

#include "bsprt/error.h"
#include "bsprt/io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = "/tmp/bsprt_fuzz_rays_" + std::to_string(getpid());
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  }
  try {
    const auto rays = bsprt::read_rays(path);
    if (16 + rays.size() * sizeof(bsprt::Ray) != size) __builtin_trap();
  } catch (const bsprt::InputError&) {
  }
  try {
    const auto hits = bsprt::read_hits(path);
    if (16 + hits.size() * sizeof(bsprt::Hit) != size) __builtin_trap();
  } catch (const bsprt::InputError&) {
  }
  std::remove(path.c_str());
  return 0;
}
