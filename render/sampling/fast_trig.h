// sin, cos and atan for the warps, where the angle is already confined to an octant: polynomials
// of minimax error below a float ulp (sin 1e-8 relative, cos 1e-10, atan 2e-8 relative, fitted by
// Lawson's reweighted least squares), without libm's range reduction and special cases. libm's
// sincosf and atanf were 2.5 % of a brdf sample and 4.6 % of a mis sample (perf, Cornell box).
#pragma once
#include <numbers>

namespace vpl::fast {

struct SinCos {
  float sin, cos;
};

// For |x| <= pi / 4; T is float or a vector of floats (render/integrator/path_lanes: eight at once).
template <class T>
inline void sinCosOctant(const T& x, T& s, T& c) {  // by reference: see offsetCoordinates (accel.h)
  const T z = x * x;
  s = x + x * z * (-0.16666659411f + z * (0.0083324080842f + z * -0.00019543791327f));
  c = 1.0f - 0.5f * z + z * z * (0.041666646866f + z * (-0.0013887367487f + z * 2.4438448729e-05f));
}
inline SinCos sinCosOctant(float x) {
  SinCos r;
  sinCosOctant(x, r.sin, r.cos);
  return r;
}

// sin and cos of (pi / 4) t for t in [0, 2]: the upper half folds onto the lower by cos(pi/2 - x) = sin x.
inline SinCos sinCosQuarterTurns(float t) {
  constexpr float kQuarter = std::numbers::pi_v<float> / 4.0f;
  if (t <= 1.0f) return sinCosOctant(kQuarter * t);
  const SinCos f = sinCosOctant(kQuarter * (2.0f - t));
  return {f.cos, f.sin};
}

// atan(a) for a in [0, 1]; above tan(pi / 8), atan a = pi / 4 + atan((a - 1) / (a + 1)) keeps the
// polynomial's argument within +-tan(pi / 8).
inline float atanUnit(float a) {
  constexpr float kTanEighth = 0.41421356237f;
  float offset = 0.0f;
  if (a > kTanEighth) {
    offset = std::numbers::pi_v<float> / 4.0f;
    a = (a - 1.0f) / (a + 1.0f);
  }
  const float z = a * a;
  return offset + a + a * z * (-0.33332949152f + z * (0.19977710436f + z * (-0.13877682547f + z * 0.080537336151f)));
}

// atan2(y, x) for x, y >= 0 (0 when both are), in [0, pi / 2].
inline float atan2Quadrant(float y, float x) {
  if (!(x > 0.0f || y > 0.0f)) return 0.0f;
  return y <= x ? atanUnit(y / x) : std::numbers::pi_v<float> / 2.0f - atanUnit(x / y);
}

}  // namespace vpl::fast
