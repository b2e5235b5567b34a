// Small 3-vector and colour value types shared by the whole tracer.
// Vec3<T> is a plain aggregate (no invariants); Vec3d carries the host-side
// scene as parsed, Vec3f the packed database and the traversal arithmetic.
#pragma once

#include <cmath>

namespace tracer {

template <class T>
struct Vec3 {
  T x{}, y{}, z{};

  constexpr T operator[](int axis) const { return axis == 0 ? x : axis == 1 ? y : z; }
  constexpr T& operator[](int axis) { return axis == 0 ? x : axis == 1 ? y : z; }

  constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3 operator-() const { return {-x, -y, -z}; }
  constexpr Vec3 operator*(T s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3 operator/(T s) const { return {x / s, y / s, z / s}; }
  constexpr Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
  constexpr Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
  constexpr Vec3& operator*=(T s) { x *= s; y *= s; z *= s; return *this; }
  constexpr bool operator==(const Vec3&) const = default;

  template <class U>
  constexpr explicit operator Vec3<U>() const {
    return {static_cast<U>(x), static_cast<U>(y), static_cast<U>(z)};
  }
};

template <class T> constexpr Vec3<T> operator*(T s, const Vec3<T>& v) { return v * s; }
template <class T> constexpr T dot(const Vec3<T>& a, const Vec3<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T> constexpr Vec3<T> cross(const Vec3<T>& a, const Vec3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T> T length(const Vec3<T>& v) { return std::sqrt(dot(v, v)); }
template <class T> Vec3<T> normalize(const Vec3<T>& v) { return v / length(v); }
template <class T> constexpr Vec3<T> min(const Vec3<T>& a, const Vec3<T>& b) {
  return {a.x < b.x ? a.x : b.x, a.y < b.y ? a.y : b.y, a.z < b.z ? a.z : b.z};
}
template <class T> constexpr Vec3<T> max(const Vec3<T>& a, const Vec3<T>& b) {
  return {a.x > b.x ? a.x : b.x, a.y > b.y ? a.y : b.y, a.z > b.z ? a.z : b.z};
}

using Vec3d = Vec3<double>;
using Vec3f = Vec3<float>;

// Linear RGB, nominally 0..1 per channel (not clamped until output).
struct Color {
  float r{}, g{}, b{};

  constexpr Color operator+(const Color& o) const { return {r + o.r, g + o.g, b + o.b}; }
  constexpr Color operator*(const Color& o) const { return {r * o.r, g * o.g, b * o.b}; }
  constexpr Color operator*(float s) const { return {r * s, g * s, b * s}; }
  constexpr Color& operator+=(const Color& o) { r += o.r; g += o.g; b += o.b; return *this; }
  constexpr bool operator==(const Color&) const = default;
  constexpr float max_component() const { return r > g ? (r > b ? r : b) : (g > b ? g : b); }
};

}  // namespace tracer
