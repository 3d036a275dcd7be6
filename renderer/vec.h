// Small fixed-size vectors for geometry set-up (the hot loops in raycast/
// work on plain float arrays).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

namespace pvr::core {

template <typename T>
struct Vec3T {
  T x = 0, y = 0, z = 0;

  constexpr T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr const T& operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }

  friend constexpr Vec3T operator+(Vec3T a, Vec3T b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend constexpr Vec3T operator-(Vec3T a, Vec3T b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend constexpr Vec3T operator-(Vec3T a) { return {-a.x, -a.y, -a.z}; }
  friend constexpr Vec3T operator*(Vec3T a, T s) { return {a.x * s, a.y * s, a.z * s}; }
  friend constexpr Vec3T operator*(T s, Vec3T a) { return a * s; }
  friend constexpr Vec3T operator/(Vec3T a, T s) { return {a.x / s, a.y / s, a.z / s}; }
  friend constexpr bool operator==(Vec3T a, Vec3T b) = default;
};

using Vec3 = Vec3T<double>;

template <typename T>
constexpr T dot(Vec3T<T> a, Vec3T<T> b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <typename T>
constexpr Vec3T<T> cross(Vec3T<T> a, Vec3T<T> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <typename T>
T length(Vec3T<T> a) { return std::sqrt(dot(a, a)); }
template <typename T>
Vec3T<T> normalize(Vec3T<T> a) { return a / length(a); }
// v turned right-handedly by `radians` about the unit axis k (Rodrigues).
template <typename T>
Vec3T<T> rotateAbout(Vec3T<T> v, Vec3T<T> k, T radians) {
  const T c = std::cos(radians), s = std::sin(radians);
  return v * c + cross(k, v) * s + k * (dot(k, v) * (1 - c));
}

// Integer node coordinates (voxel indices).
struct IVec3 {
  std::int64_t x = 0, y = 0, z = 0;
  constexpr std::int64_t& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr const std::int64_t& operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  friend constexpr bool operator==(IVec3 a, IVec3 b) = default;
  constexpr std::int64_t product() const { return x * y * z; }
};

}  // namespace pvr::core
