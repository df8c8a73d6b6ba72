#pragma once
/// \file io.h
/// The `.rays` and `.hits` files every bsprt tool (and Embree) reads (formats.md).

#include <span>
#include <string>
#include <vector>

#include "bsprt/ray.h"

namespace bsprt {

/// Reads a `.rays` file; throws InputError on bad magic, version or size.
std::vector<Ray> read_rays(const std::string& path);
/// Writes a `.rays` file; throws InputError when it cannot be written.
void write_rays(const std::string& path, std::span<const Ray> rays);
/// Reads a `.hits` file; same checks as read_rays, and every record must be a
/// hit record formats.md allows (hit_record_problem, bsprt/compare.h).
std::vector<Hit> read_hits(const std::string& path);
/// Writes a `.hits` file; throws UsageError (writing nothing) for a record
/// read_hits would refuse, InputError when the file cannot be written.
void write_hits(const std::string& path, std::span<const Hit> hits);

}  // namespace bsprt
