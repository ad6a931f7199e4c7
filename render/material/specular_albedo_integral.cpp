#include "render/material/specular_albedo_integral.h"

#include <algorithm>
#include <cmath>
#include "render/material/ggx.h"

namespace vpl {

namespace {

constexpr int kMu = SpecularAlbedoTable::kMu, kAlpha = SpecularAlbedoTable::kAlpha;
constexpr int kSamples = 32;  // kSamples^2 stratified samples per entry

// Rows are uniform in sqrt(alpha) = perceptual roughness, where E changes fastest.
float alphaOfRow(int j) {
  const float r = float(j) / float(kAlpha - 1);
  return std::max(r * r, 1e-3f);
}
float muOfColumn(int i) { return std::max(float(i) / float(kMu - 1), 1e-3f); }

AlbedoTerms integrate(float mu, float alpha) {
  // E = E_h[F G2 / G1(wo)] with h drawn from the visible normals of wo (the sampling weight).
  const glm::vec3 wo(std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, mu);
  double a = 0.0, b = 0.0;
  for (int s = 0; s < kSamples; ++s)
    for (int t = 0; t < kSamples; ++t) {
      const glm::vec2 u((s + 0.5f) / kSamples, (t + 0.5f) / kSamples);
      const glm::vec3 h = ggx::sampleVisibleNormal(wo, u, alpha);
      const float cosOH = glm::dot(wo, h);
      const glm::vec3 wi = 2.0f * cosOH * h - wo;
      if (wi.z <= 0.0f || cosOH <= 0.0f) continue;
      const float weight = ggx::G2(wo, wi, alpha) / ggx::G1(wo, alpha);
      const float m = 1.0f - cosOH, m5 = m * m * m * m * m;
      a += weight * (1.0f - m5);
      b += weight * m5;
    }
  const double n = double(kSamples) * kSamples;
  return {float(a / n), float(b / n)};
}

}  // namespace

SpecularAlbedoTable integrateSpecularAlbedoTable() {
  SpecularAlbedoTable t;
  for (int j = 0; j < kAlpha; ++j) {
    for (int i = 0; i < kMu; ++i) t.e[j * kMu + i] = integrate(muOfColumn(i), alphaOfRow(j));
    // 2 * integral E(mu) mu dmu by the trapezoid rule on the table's own columns, so the
    // coupling's normaliser matches the interpolated E it is used with.
    double avgA = 0.0, avgB = 0.0;
    for (int i = 0; i + 1 < kMu; ++i) {
      const float m0 = float(i) / (kMu - 1), m1 = float(i + 1) / (kMu - 1);
      avgA += 0.5 * (t.e[j * kMu + i].a * m0 + t.e[j * kMu + i + 1].a * m1) * (m1 - m0);
      avgB += 0.5 * (t.e[j * kMu + i].b * m0 + t.e[j * kMu + i + 1].b * m1) * (m1 - m0);
    }
    t.average[j] = {float(2.0 * avgA), float(2.0 * avgB)};
  }
  return t;
}

}  // namespace vpl
