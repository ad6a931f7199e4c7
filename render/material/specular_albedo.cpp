#include "render/material/specular_albedo.h"

#include <algorithm>
#include <cmath>
#include "render/material/specular_albedo_integral.h"

namespace vpl {

namespace {

constexpr int kMu = SpecularAlbedoTable::kMu, kAlpha = SpecularAlbedoTable::kAlpha;

// The integral's values (specular_albedo_integral.cpp), embedded: no process pays for them at start.
constexpr SpecularAlbedoTable kTable =
#include "render/material/specular_albedo_values.inc"
    ;

void rowOf(float alpha, int& j0, float& tj) {
  const float r = std::sqrt(std::clamp(alpha, 0.0f, 1.0f)) * (kAlpha - 1);
  j0 = std::min(int(r), kAlpha - 2);
  tj = r - float(j0);
}

}  // namespace

const SpecularAlbedoTable& embeddedSpecularAlbedoTable() { return kTable; }

AlbedoTerms specularAlbedo(float mu, float alpha) {
  const SpecularAlbedoTable& t = kTable;
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
  const SpecularAlbedoTable& t = kTable;
  int j0;
  float tj;
  rowOf(alpha, j0, tj);
  return {t.average[j0].a * (1 - tj) + t.average[j0 + 1].a * tj, t.average[j0].b * (1 - tj) + t.average[j0 + 1].b * tj};
}

}  // namespace vpl
