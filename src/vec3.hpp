// Host-side 3-vectors (scene input, figures, diagnostics). Kernels keep their
// own inlined arithmetic on View data.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

namespace capstan {

using Vec3 = std::array<double, 3>;

inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double norm(const Vec3& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }
inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
// a scaled by a power of two (exact: a direction of ordinary size keeps its
// bits) so that its largest component is in [1, 2): 1e-200 or 1e200 then
// neither under- nor overflow |a|^2. a must be finite and non-zero.
inline Vec3 scaledDirection(const Vec3& a) {
  const double m = std::max({std::fabs(a[0]), std::fabs(a[1]), std::fabs(a[2])});
  return {std::ldexp(a[0], -std::ilogb(m)), std::ldexp(a[1], -std::ilogb(m)), std::ldexp(a[2], -std::ilogb(m))};
}
// a / |a| (an axis direction; the scene reader rejects zero ones).
inline Vec3 unit(const Vec3& a) {
  const double n = norm(a);
  return {a[0] / n, a[1] / n, a[2] / n};
}

}  // namespace capstan
