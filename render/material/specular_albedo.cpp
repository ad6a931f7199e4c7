#include "render/material/specular_albedo.h"

#include <algorithm>
#include <array>
#include <cmath>
#include "render/material/ggx.h"

namespace vpl {

namespace {

constexpr int kMu = 32, kAlpha = 32, kSamples = 32;  // kSamples^2 stratified samples per entry

struct Table {
  std::array<AlbedoTerms, kMu * kAlpha> e;
  std::array<AlbedoTerms, kAlpha> average;
};

// Table rows are uniform in sqrt(alpha) = perceptual roughness, where E changes fastest.
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

Table buildTable() {
  Table t;
  {
    for (int j = 0; j < kAlpha; ++j) {
      double avgA = 0.0, avgB = 0.0;
      for (int i = 0; i < kMu; ++i) {
        t.e[j * kMu + i] = integrate(muOfColumn(i), alphaOfRow(j));
      }
      // 2 * integral E(mu) mu dmu by the trapezoid rule on the table's own columns, so the
      // coupling's normaliser matches the interpolated E it is used with.
      for (int i = 0; i + 1 < kMu; ++i) {
        const float m0 = float(i) / (kMu - 1), m1 = float(i + 1) / (kMu - 1);
        avgA += 0.5 * (t.e[j * kMu + i].a * m0 + t.e[j * kMu + i + 1].a * m1) * (m1 - m0);
        avgB += 0.5 * (t.e[j * kMu + i].b * m0 + t.e[j * kMu + i + 1].b * m1) * (m1 - m0);
      }
      t.average[j] = {float(2.0 * avgA), float(2.0 * avgB)};
    }
  }
  return t;
}

// Built on first use (a few milliseconds); a function-local static is thread-safe and cheap to check.
const Table& table() {
  static const Table t = buildTable();
  return t;
}

void rowOf(float alpha, int& j0, float& tj) {
  const float r = std::sqrt(std::clamp(alpha, 0.0f, 1.0f)) * (kAlpha - 1);
  j0 = std::min(int(r), kAlpha - 2);
  tj = r - float(j0);
}

}  // namespace

AlbedoTerms specularAlbedo(float mu, float alpha) {
  const Table& t = table();
  int j0;
  float tj;
  rowOf(alpha, j0, tj);
  const float x = std::clamp(mu, 0.0f, 1.0f) * (kMu - 1);
  const int i0 = std::min(int(x), kMu - 2);
  const float ti = x - float(i0);
  auto at = [&](int i, int j) { return t.e[j * kMu + i]; };
  const AlbedoTerms e00 = at(i0, j0), e10 = at(i0 + 1, j0), e01 = at(i0, j0 + 1), e11 = at(i0 + 1, j0 + 1);
  auto lerp2 = [&](float v00, float v10, float v01, float v11) {
    return (v00 * (1 - ti) + v10 * ti) * (1 - tj) + (v01 * (1 - ti) + v11 * ti) * tj;
  };
  return {lerp2(e00.a, e10.a, e01.a, e11.a), lerp2(e00.b, e10.b, e01.b, e11.b)};
}

AlbedoTerms averageSpecularAlbedo(float alpha) {
  const Table& t = table();
  int j0;
  float tj;
  rowOf(alpha, j0, tj);
  return {t.average[j0].a * (1 - tj) + t.average[j0 + 1].a * tj, t.average[j0].b * (1 - tj) + t.average[j0 + 1].b * tj};
}

}  // namespace vpl
