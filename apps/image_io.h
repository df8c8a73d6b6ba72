#pragma once
/// \file image_io.h
/// Images in linear RGB floats, written as 8-bit sRGB PNG (stb_image_write) or
/// raw radiance PFM.

#include <string>
#include <vector>

namespace bsprt {

/// Linear RGB image, row-major from the top-left pixel.
struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  ///< 3 * width * height values
  Image() = default;
  Image(int w, int h) : width(w), height(h), rgb(std::size_t(3) * w * h, 0.0f) {}
  float* pixel(int x, int y) { return &rgb[(std::size_t(y) * width + x) * 3]; }
  const float* pixel(int x, int y) const { return &rgb[(std::size_t(y) * width + x) * 3]; }
};

/// Writes an 8-bit sRGB PNG; throws InputError when the file cannot be written.
void write_png(const std::string& path, const Image& image);
/// Writes a little-endian PFM (linear floats, bottom row first as PFM wants).
void write_pfm(const std::string& path, const Image& image);

}  // namespace bsprt
