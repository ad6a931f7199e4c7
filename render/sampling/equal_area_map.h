// Clarberg's equal-area octahedral map between the unit square and the unit sphere ("Fast
// Equal-Area Mapping of the (Hemi)Sphere using SIMD", JGT 2008). Equal area is what makes it a
// sampling tool: every cell of a regular grid on the square covers the same solid angle, 4 pi / N,
// and a uniform point in a cell is a uniform direction within it.
#pragma once
#include <algorithm>
#include <cmath>
#include <numbers>
#include <glm/glm.hpp>
#include "render/sampling/fast_trig.h"

namespace vpl {

inline glm::vec3 equalAreaSquareToSphere(glm::vec2 p) {
  const float a = 2.0f * p.x - 1.0f, b = 2.0f * p.y - 1.0f;
  const float ap = std::abs(a), bp = std::abs(b);
  const float signedDistance = 1.0f - (ap + bp);  // > 0: upper hemisphere
  const float r = 1.0f - std::abs(signedDistance);
  // The azimuth within the quadrant, in quarter turns of pi / 4: [0, 2].
  const float turns = std::clamp(r == 0.0f ? 1.0f : (bp - ap) / r + 1.0f, 0.0f, 2.0f);
  const fast::SinCos phi = fast::sinCosQuarterTurns(turns);
  const float z = std::copysign(1.0f - r * r, signedDistance);
  const float s = r * std::sqrt(std::max(0.0f, 2.0f - r * r));
  return {std::copysign(phi.cos, a) * s, std::copysign(phi.sin, b) * s, z};
}

// Inverse of equalAreaSquareToSphere for unit vectors; the result lies in [0, 1]^2.
inline glm::vec2 equalAreaSphereToSquare(const glm::vec3& d) {
  const float x = std::abs(d.x), y = std::abs(d.y), z = std::abs(d.z);
  const float r = std::sqrt(std::max(0.0f, 1.0f - z));
  const float phi = fast::atan2Quadrant(y, x) * (2.0f / std::numbers::pi_v<float>);  // [0, 1] within the quadrant
  float v = phi * r, u = r - v;
  if (d.z < 0.0f) {
    std::swap(u, v);
    u = 1.0f - u;
    v = 1.0f - v;
  }
  u = std::copysign(u, d.x);
  v = std::copysign(v, d.y);
  return {std::clamp(0.5f * (u + 1.0f), 0.0f, 1.0f), std::clamp(0.5f * (v + 1.0f), 0.0f, 1.0f)};
}

// Row-major cell of a direction on a resolution x resolution grid over the square.
inline int equalAreaCell(const glm::vec3& d, int resolution) {
  const glm::vec2 p = equalAreaSphereToSquare(d);
  const int ix = std::min(int(p.x * float(resolution)), resolution - 1);
  const int iy = std::min(int(p.y * float(resolution)), resolution - 1);
  return iy * resolution + ix;
}

}  // namespace vpl
