#pragma once
/// \file ray_io.h
/// Reading and writing `.rays` and `.hits` files (shared/formats.md).

#include <span>
#include <string>
#include <vector>

#include "geometry/ray.h"

namespace bsprt {

/// Reads a `.rays` file; throws InputError on bad magic, version, or a size that
/// does not match N (truncated or trailing bytes).
std::vector<Ray> read_rays(const std::string& path);
/// Writes a `.rays` file; throws InputError when the file cannot be written.
void write_rays(const std::string& path, std::span<const Ray> rays);

/// Reads a `.hits` file; same checks as read_rays.
std::vector<Hit> read_hits(const std::string& path);
/// Writes a `.hits` file.
void write_hits(const std::string& path, std::span<const Hit> hits);

}  // namespace bsprt
