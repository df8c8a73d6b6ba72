#pragma once
/// \file ray.h
/// Ray and hit records, byte-compatible with the records of the `.rays` and
/// `.hits` files of shared/formats.md so files map straight onto them.

#include <cmath>
#include <cstdint>
#include <limits>

#include "bsprt/vec3.h"

namespace bsprt {

/// A ray org + t*dir for t in [tnear, tfar]; dir need not be normalized.
/// Layout = the 32-byte `.rays` record: org[3], tnear, dir[3], tfar.
struct Ray {
  Vec3f org;
  float tnear = 0.0f;
  Vec3f dir;
  float tfar = std::numeric_limits<float>::infinity();
};
static_assert(sizeof(Ray) == 32, "Ray must match the .rays record");

/// Triangle number of a miss.
inline constexpr std::uint32_t kNoHit = 0xFFFFFFFFu;

/// Nearest hit: t, triangle number, barycentrics of v1 and v2.
/// Layout = the 16-byte `.hits` record. A miss is t=+inf, prim=kNoHit, u=v=0.
struct Hit {
  float t = std::numeric_limits<float>::infinity();
  std::uint32_t prim = kNoHit;
  float u = 0.0f;
  float v = 0.0f;

  bool hit() const { return prim != kNoHit; }
};
static_assert(sizeof(Hit) == 16, "Hit must match the .hits record");

/// True when the ray can hit anything: finite origin and direction, non-zero
/// direction, tnear <= tfar, tnear not NaN (formats.md: anything else misses).
inline bool is_valid(const Ray& r) {
  return is_finite(r.org) && is_finite(r.dir) && !(r.dir.x == 0 && r.dir.y == 0 && r.dir.z == 0) &&
         !std::isnan(r.tnear) && !std::isnan(r.tfar) && r.tnear <= r.tfar;
}

}  // namespace bsprt
