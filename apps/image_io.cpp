#include "apps/image_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>

#include "bsprt/error.h"

#include <stb_image_write.h>

namespace bsprt {
namespace {
std::uint8_t to_srgb8(float v) {
  if (!(v > 0.0f)) return 0;  // also maps NaN to black
  v = std::min(v, 1.0f);
  const float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
  return std::uint8_t(std::lround(s * 255.0f));
}
}  // namespace

void write_png(const std::string& path, const Image& image) {
  std::vector<std::uint8_t> bytes(image.rgb.size());
  std::transform(image.rgb.begin(), image.rgb.end(), bytes.begin(), to_srgb8);
  if (!stbi_write_png(path.c_str(), image.width, image.height, 3, bytes.data(), image.width * 3))
    throw InputError(path, "cannot write PNG file");
}

void write_pfm(const std::string& path, const Image& image) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError(path, "cannot open for writing");
  out << "PF\n" << image.width << " " << image.height << "\n-1\n";
  for (int y = image.height - 1; y >= 0; --y)
    out.write(reinterpret_cast<const char*>(image.pixel(0, y)), std::streamsize(sizeof(float) * 3 * image.width));
  if (!out) throw InputError(path, "write failed");
}

}  // namespace bsprt
