#pragma once
/// \file vec3.h
/// Small fixed-size vectors and boxes used everywhere: vertex positions, ray
/// origins and directions, bounds. Float for the scene, double for steering
/// computations (areas, error bounds). Exact work lives in robust/.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace bsprt {

/// A 3-vector; T is float for scene data and double where more range helps.
template <typename T>
struct Vec3 {
  T x = 0, y = 0, z = 0;

  constexpr Vec3() = default;
  constexpr Vec3(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
  template <typename U>
  constexpr explicit Vec3(const Vec3<U>& o) : x(T(o.x)), y(T(o.y)), z(T(o.z)) {}

  /// Component i (0, 1 or 2). Through a table of member pointers: one indexed
  /// load, no compare chain, for the run-time axes of the traversals
  /// (shear axes, split axes), which are unpredictable on incoherent rays.
  constexpr T operator[](int i) const { return this->*kMembers[i]; }
  constexpr T& operator[](int i) { return this->*kMembers[i]; }

 private:
  static constexpr T Vec3::*kMembers[3] = {&Vec3::x, &Vec3::y, &Vec3::z};

 public:

  constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3 operator-() const { return {-x, -y, -z}; }
  constexpr Vec3 operator*(T s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3 operator/(T s) const { return {x / s, y / s, z / s}; }
  constexpr Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
  constexpr Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
  constexpr Vec3& operator*=(T s) { x *= s; y *= s; z *= s; return *this; }
  constexpr bool operator==(const Vec3& o) const { return x == o.x && y == o.y && z == o.z; }
  constexpr bool operator!=(const Vec3& o) const { return !(*this == o); }
};

using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;

template <typename T> constexpr Vec3<T> operator*(T s, const Vec3<T>& v) { return v * s; }
template <typename T> constexpr T dot(const Vec3<T>& a, const Vec3<T>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <typename T> constexpr Vec3<T> cross(const Vec3<T>& a, const Vec3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <typename T> T length(const Vec3<T>& a) { return std::sqrt(dot(a, a)); }
template <typename T> Vec3<T> normalize(const Vec3<T>& a) { return a / length(a); }
template <typename T> constexpr Vec3<T> min(const Vec3<T>& a, const Vec3<T>& b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
template <typename T> constexpr Vec3<T> max(const Vec3<T>& a, const Vec3<T>& b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
template <typename T> Vec3<T> abs(const Vec3<T>& a) { return {std::abs(a.x), std::abs(a.y), std::abs(a.z)}; }
template <typename T> bool is_finite(const Vec3<T>& a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
/// Index (0, 1, 2) of the component with the largest magnitude.
template <typename T> constexpr int max_axis(const Vec3<T>& a) {
  const T ax = a.x < 0 ? -a.x : a.x, ay = a.y < 0 ? -a.y : a.y, az = a.z < 0 ? -a.z : a.z;
  return ax >= ay ? (ax >= az ? 0 : 2) : (ay >= az ? 1 : 2);
}

/// Axis-aligned box; an empty box has lo > hi and absorbs nothing.
template <typename T>
struct Box3 {
  Vec3<T> lo{std::numeric_limits<T>::infinity(), std::numeric_limits<T>::infinity(),
             std::numeric_limits<T>::infinity()};
  Vec3<T> hi{-std::numeric_limits<T>::infinity(), -std::numeric_limits<T>::infinity(),
             -std::numeric_limits<T>::infinity()};

  constexpr void extend(const Vec3<T>& p) { lo = min(lo, p); hi = max(hi, p); }
  constexpr void extend(const Box3& b) { lo = min(lo, b.lo); hi = max(hi, b.hi); }
  constexpr bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  constexpr Vec3<T> diagonal() const { return hi - lo; }
  constexpr Vec3<T> center() const { return (lo + hi) * T(0.5); }
  /// Surface area; 0 for an empty box.
  constexpr T area() const {
    if (empty()) return 0;
    const Vec3<T> d = diagonal();
    return 2 * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
};

using Box3f = Box3<float>;
using Box3d = Box3<double>;

}  // namespace bsprt
