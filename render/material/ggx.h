// GGX (Trowbridge-Reitz) microfacet distribution with Smith masking, in the local shading frame
// (normal on +z). Walter et al. 2007; visible-normal sampling after Heitz 2018.
#pragma once
#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include "render/sampling/warps.h"

namespace vpl::ggx {

inline float D(const glm::vec3& h, float alpha) {
  const float a2 = alpha * alpha;
  const float c2 = h.z * h.z;
  const float denom = c2 * (a2 - 1.0f) + 1.0f;
  return a2 / (kPi * denom * denom);
}

// Smith Lambda for direction w (its cosine with the normal is w.z > 0).
inline float lambda(const glm::vec3& w, float alpha) {
  const float c2 = w.z * w.z;
  const float s2 = std::max(0.0f, 1.0f - c2);
  if (s2 <= 0.0f) return 0.0f;
  const float a2tan2 = alpha * alpha * s2 / std::max(c2, 1e-20f);
  return 0.5f * (-1.0f + std::sqrt(1.0f + a2tan2));
}

inline float G1(const glm::vec3& w, float alpha) { return 1.0f / (1.0f + lambda(w, alpha)); }
// Height-correlated masking-shadowing (Heitz 2014, eq. 99).
inline float G2(const glm::vec3& wo, const glm::vec3& wi, float alpha) {
  return 1.0f / (1.0f + lambda(wo, alpha) + lambda(wi, alpha));
}

// A visible normal for wo (Heitz 2018, "Sampling the GGX Distribution of Visible Normals").
inline glm::vec3 sampleVisibleNormal(const glm::vec3& wo, glm::vec2 u, float alpha) {
  const glm::vec3 vh = glm::normalize(glm::vec3(alpha * wo.x, alpha * wo.y, wo.z));
  const float lensq = vh.x * vh.x + vh.y * vh.y;
  const glm::vec3 t1 = lensq > 0.0f ? glm::vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq) : glm::vec3(1, 0, 0);
  const glm::vec3 t2 = glm::cross(vh, t1);
  const float r = std::sqrt(u.x), phi = 2.0f * kPi * u.y;
  const float p1 = r * std::cos(phi);
  const float s = 0.5f * (1.0f + vh.z);
  const float p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * r * std::sin(phi);
  const glm::vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return glm::normalize(glm::vec3(alpha * nh.x, alpha * nh.y, std::max(1e-7f, nh.z)));
}

// Density of wi = reflect(wo, h) when h is a visible normal of wo: D_wo(h) / (4 wo.h) = G1(wo) D(h) / (4 wo.z),
// from wo's Smith Lambda, D(h) and wo.z, which the BSDF has in hand.
inline float reflectionPdf(float lambdaOut, float d, float cosOut) {
  return 1.0f / (1.0f + lambdaOut) * d / (4.0f * cosOut);
}

// Schlick's Fresnel with an explicit grazing value f90 (1 for the classic form).
inline glm::vec3 schlick(const glm::vec3& f0, float f90, float cosTheta) {
  const float m = std::clamp(1.0f - cosTheta, 0.0f, 1.0f);
  const float m5 = (m * m) * (m * m) * m;
  return f0 + (glm::vec3(f90) - f0) * m5;
}

}  // namespace vpl::ggx
