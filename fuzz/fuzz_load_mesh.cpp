// libFuzzer harness for the mesh loaders: the first byte picks the format
// (obj, ply, off, stl), the rest is the file. Loading must either succeed with
// indices in range or throw InputError; anything else (crash, other exception,
// sanitizer report) is a finding.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

#include "bsprt/error.h"
#include "geometry/io/load_mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* kExt[] = {".obj", ".ply", ".off", ".stl"};
  const std::string path = "/tmp/bsprt_fuzz_" + std::to_string(getpid()) + kExt[data[0] % 4];
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(data + 1), std::streamsize(size - 1));
  }
  try {
    bsprt::LoadOptions options;
    options.allow_nonfinite = (data[0] & 4) != 0;
    const bsprt::TriangleSoup soup = bsprt::load_mesh(path, options);
    for (const auto& t : soup.triangles)
      for (std::uint32_t i : t)
        if (i >= soup.vertices.size()) __builtin_trap();  // an index the loader let through
    if (soup.degenerate.size() != soup.triangles.size()) __builtin_trap();
  } catch (const bsprt::InputError&) {
    // expected for malformed input
  }
  std::remove(path.c_str());
  return 0;
}
