// Warps from the unit square to directions and points, with their densities. Local frames have
// the axis on +z; u is uniform in [0,1)^2.
#pragma once
#include <algorithm>
#include <cmath>
#include <numbers>
#include <glm/glm.hpp>
#include "render/sampling/fast_trig.h"

namespace vpl {

inline constexpr float kPi = std::numbers::pi_v<float>;
inline constexpr float kInvPi = 1.0f / kPi;
inline constexpr float kInv4Pi = 0.25f / kPi;

inline glm::vec3 sampleUniformSphere(glm::vec2 u) {
  const float z = 1.0f - 2.0f * u.x;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float uniformSpherePdf() { return kInv4Pi; }

inline glm::vec3 sampleUniformHemisphere(glm::vec2 u) {
  const float z = u.x;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float uniformHemispherePdf() { return 0.5f * kInvPi; }

// Shirley & Chiu's concentric map: low distortion, so stratified u stay stratified.
inline glm::vec2 sampleConcentricDisk(glm::vec2 u) {
  const glm::vec2 o = 2.0f * u - 1.0f;
  if (o.x == 0.0f && o.y == 0.0f) return {0.0f, 0.0f};
  // The angle is pi/4 (o.y / o.x) in the wedges about the x axis, pi/2 - pi/4 (o.x / o.y) about y.
  // Selects, not branches: the wedge is a coin flip per sample, which a branch predictor loses.
  const bool aboutX = std::abs(o.x) > std::abs(o.y);
  const float radius = aboutX ? o.x : o.y;
  const fast::SinCos a = fast::sinCosOctant(0.25f * kPi * ((aboutX ? o.y : o.x) / radius));
  return radius * glm::vec2(aboutX ? a.cos : a.sin, aboutX ? a.sin : a.cos);
}

// Malley's method: project the disk up to the hemisphere.
inline glm::vec3 sampleCosineHemisphere(glm::vec2 u) {
  const glm::vec2 d = sampleConcentricDisk(u);
  const float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
  return {d.x, d.y, z};
}
inline float cosineHemispherePdf(float cosTheta) { return cosTheta > 0.0f ? cosTheta * kInvPi : 0.0f; }

// A cone about +z given by 1 - cos of its half-angle, carried explicitly. Below about 0.02 degrees
// cos(theta) rounds to 1 in float, and well above that 1 - cos(theta) from a float cosine has lost
// digits (2 % at 0.1 degrees, 1e-4 at 1 degree); 2 sin^2(theta / 2) keeps them all. Take the cone from
// its angle whenever the angle is known; fromCos is exact only for the cosine as given.
struct Cone {
  float oneMinusCos = 1.0f;  // in [0, 2]

  static Cone fromAngle(float theta) {
    const float s = std::sin(0.5f * std::clamp(theta, 0.0f, kPi));
    return {2.0f * s * s};
  }
  static Cone fromCos(float cosTheta) { return {1.0f - std::clamp(cosTheta, -1.0f, 1.0f)}; }
  float cosTheta() const { return 1.0f - oneMinusCos; }
};

// Uniform in the cone: 1 - cos(theta) is uniform in [0, cone.oneMinusCos], phi in [0, 2 pi).
inline glm::vec3 sampleUniformCone(glm::vec2 u, Cone cone) {
  const float oneMinusCos = u.x * cone.oneMinusCos;
  const float cosTheta = 1.0f - oneMinusCos;
  // sin^2 = (1 - cos)(1 + cos): no cancellation for small angles.
  const float sinTheta = std::sqrt(std::max(0.0f, oneMinusCos * (2.0f - oneMinusCos)));
  const float phi = 2.0f * kPi * u.y;
  return {sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta};
}
// 1 / solid angle. The floor keeps a zero-size cone finite (1.6e29); no real cone reaches it.
inline float uniformConePdf(Cone cone) { return 1.0f / (2.0f * kPi * std::max(cone.oneMinusCos, 1e-30f)); }

// Uniform barycentrics (b1, b2) on a triangle; b0 = 1 - b1 - b2 (Heitz's low-distortion map, 2019).
inline glm::vec2 sampleUniformTriangle(glm::vec2 u) {
  float b0, b1;
  if (u.x < u.y) {
    b0 = u.x / 2.0f;
    b1 = u.y - b0;
  } else {
    b1 = u.y / 2.0f;
    b0 = u.x - b1;
  }
  return {b1, 1.0f - b0 - b1};
}

}  // namespace vpl
