#include "render/scene/emitters.h"

#include <algorithm>
#include <numbers>
#include "render/core/color.h"
#include "render/core/frame.h"
#include "render/sampling/warps.h"

namespace vpl {

namespace {


// glTF KHR_lights_punctual spot attenuation: smooth between the outer and inner cone cosines, full
// intensity inside the inner cone however narrow it is. (The spec's reference code floors
// cos_inner - cos_outer at 1e-3, which dims every spot narrower than about 2.6 degrees at its very
// centre: a 1-degree spot to 2 % of its intensity.) Coincident cones give a hard edge.
float spotAttenuation(const PunctualLight& light, const glm::vec3& travel) {
  if (light.type != LightType::Spot) return 1.0f;
  const float cd = glm::dot(glm::normalize(light.direction), travel);
  const float width = light.cosInner - light.cosOuter;
  if (!(width > 0.0f)) return cd >= light.cosOuter ? 1.0f : 0.0f;
  const float t = glm::clamp((cd - light.cosOuter) / width, 0.0f, 1.0f);
  return t * t;
}

// The spec's recommended range window (KHR_lights_punctual, "Range Property").
float rangeWindow(const PunctualLight& light, float distance) {
  if (light.range <= 0.0f) return 1.0f;
  const float r = distance / light.range;
  const float w = glm::clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
  return w * w;
}

// When a triangle is sampled by solid angle rather than by area (EmitterSet::kSolidAngleSpread, used by
// solidAngleStrategy below).
//
// Area sampling has the solid-angle density d^2 / (cos A) = d^3 / (h A) at a point at distance d
// from p, with h the distance from p to the triangle's plane, so over the triangle it varies by
// (d_max / d_min)^3 <= (1 + D / d_min)^3, D the longest edge; d_min is bounded from below cheaply by
// max(h, |centroid - p| - radius of the bounding sphere). Above kSolidAngleSpread = D / d_min that
// bound exceeds 1.75^3 = 5.4 and the triangle is sampled by solid angle. Measured (brdf, 64 spp,
// 3 seeds, against 4096-spp references, against area sampling alone): lowering the threshold to
// 0.5 or 0.1 buys little more (Cornell box relMSE -4.4 % and -4.8 % against -3.7 % at 0.75) for
// 9 % and 21 % more CPU time there (against 2.6 %), where the Arvo sampler's ~150 ns is a large
// share of a path vertex; at 1 the Cornell box gains nothing. The receiver's cosine is part of neither density, and area sampling, which
// favours the far side of a light, can follow it better (direct light at a Cornell box wall point
// 1.5 m below the light and 1 m to its side: relative variance 0.001 by area, 0.007 by solid
// angle), so a low threshold is not free of losses either.

// Guards for the spherical formulas, not for variance: below kMinSolidAngle sr (a triangle seen
// edge-on or tiny) and within kHemisphereMargin sr of a whole hemisphere (p almost on a huge
// triangle) the triangle is sampled by area. SphericalTriangle keeps its digits well beyond both
// (tests/unit/test_emitter_sampling.cpp holds it to its pdf at 4.5e-11 sr, 2e-9 sr edge-on and
// 6.5e-7 sr short of a hemisphere), so the guards have a margin; pbrt-v4's [3e-4, 6.22] is for
// the cancelling float form of Arvo's formulas.
constexpr double kMinSolidAngle = 1e-10;
constexpr double kHemisphereMargin = 1e-6;
// A point closer to an emitting triangle's plane than this share of the coordinate scale lies in
// that plane as far as the renderer can tell (rays leave surfaces 256 float ulps away, 3e-5 of the
// scale): the triangle sends it nothing. Without this, a path vertex on the back of a one-sided
// light (its reflective side) whose hit point rounded to 1e-7 below the light's plane was lit by
// the whole front hemisphere: by area sampling at a vanishing density that did not show, but by
// solid angle it made fireflies of 20x the pixel above the Cornell box's light. (EmitterSet::kPlaneTolerance.)

float averageLuminance(const Texture& texture) {
  double sum = 0.0;
  for (const glm::vec4& t : texture.texels) sum += luminance(glm::vec3(t));
  return texture.texels.empty() ? 1.0f : float(sum / double(texture.texels.size()));
}

}  // namespace

EmitterSet::EmitterSet(const SceneData& scene, const glm::vec3& sky, const glm::vec3& centre, float radius)
    : scene_(&scene), punctual_(scene.lights), sky_(sky), centre_(centre), radius_(std::max(radius, 1e-30f)) {
  std::vector<float> power;
  std::vector<float> textureLuminance(scene.textures.size(), -1.0f);
  triangleIndex_.resize(scene.meshes.size());
  for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
    const MeshData& mesh = scene.meshes[m];
    const Material& material = scene.materials[mesh.material];
    if (!material.isEmissive()) continue;
    float scale = luminance(material.emission);
    if (material.emissiveTexture >= 0) {
      float& avg = textureLuminance[size_t(material.emissiveTexture)];
      if (avg < 0.0f) avg = averageLuminance(scene.textures[size_t(material.emissiveTexture)]);
      scale *= avg;
    }
    if (!(scale > 0.0f)) continue;
    auto& index = triangleIndex_[m];
    index.assign(mesh.indices.size() / 3, -1);
    for (uint32_t t = 0; t < index.size(); ++t) {
      const glm::vec3 p0 = mesh.positions[mesh.indices[3 * t]], p1 = mesh.positions[mesh.indices[3 * t + 1]],
                      p2 = mesh.positions[mesh.indices[3 * t + 2]];
      const float area = 0.5f * glm::length(glm::cross(p1 - p0, p2 - p0));
      if (!(area > 0.0f)) continue;
      index[t] = int32_t(triangles_.size());
      const glm::vec3 centre = (p0 + p1 + p2) / 3.0f;
      const float radius = std::sqrt(std::max({glm::dot(p0 - centre, p0 - centre), glm::dot(p1 - centre, p1 - centre),
                                               glm::dot(p2 - centre, p2 - centre)}));
      const float longestEdge = std::sqrt(std::max({glm::dot(p1 - p0, p1 - p0), glm::dot(p2 - p1, p2 - p1),
                                                    glm::dot(p0 - p2, p0 - p2)}));
      const glm::vec3 extent = glm::max(glm::abs(p0), glm::max(glm::abs(p1), glm::abs(p2)));
      triangles_.push_back({m, t, area, material.doubleSided, p0, p1, p2, glm::normalize(glm::cross(p1 - p0, p2 - p0)),
                            centre, radius, longestEdge, std::max(extent.x, std::max(extent.y, extent.z)),
                            material.emissiveTexture >= 0});
      power.push_back(scale * area * kPi * (material.doubleSided ? 2.0f : 1.0f));
    }
  }
  for (const PunctualLight& light : punctual_) {
    const float l = luminance(light.intensity);
    switch (light.type) {
      case LightType::Point: power.push_back(4.0f * kPi * l); break;
      case LightType::Spot: power.push_back(2.0f * kPi * (1.0f - 0.5f * (light.cosInner + light.cosOuter)) * l); break;
      case LightType::Directional: power.push_back(kPi * radius_ * radius_ * l); break;
    }
  }
  if (luminance(sky) > 0.0f) {
    skyIndex_ = int(power.size());
    // Flux through the bounding sphere from a uniform radiance field.
    power.push_back(4.0f * kPi * kPi * radius_ * radius_ * luminance(sky));
  }
  distribution_ = AliasTable(power);
  bool foldable = !distribution_.empty();
  for (size_t i = 0; i < power.size(); ++i)
    if (distribution_.pmf(i) > 0.0f && distribution_.pmf(i) < kMinFoldedShare) foldable = false;
  if (foldable) foldedChoice_ = Distribution1D(power);
}

EmitterSet::TrianglePoint EmitterSet::trianglePoint(const TriangleLight& light, glm::vec2 b) const {
  return {light.p0 * (1.0f - b.x - b.y) + light.p1 * b.x + light.p2 * b.y, light.normal};
}

float EmitterSet::planeDistance(const glm::vec3& p, const TriangleLight& light) {
  const float h = glm::dot(light.normal, p - light.p0);
  const glm::vec3 ap = glm::abs(p);
  const float scale = std::max(light.coordinateScale, std::max(ap.x, std::max(ap.y, ap.z)));
  return std::abs(h) > kPlaneTolerance * scale ? h : NAN;
}

std::optional<SphericalTriangle> EmitterSet::solidAngleStrategy(const glm::vec3& p, const TriangleLight& light) {
  // Both sample() and pdfTriangle() decide here, from p and the triangle alone, so that the density
  // an emitter hit is weighted with is the one next-event estimation used from the same point.
  const float h = std::abs(glm::dot(light.normal, light.p0 - p));
  const float nearest = std::max(h, glm::length(light.centre - p) - light.radius);
  if (!(light.longestEdge > kSolidAngleSpread * nearest)) return std::nullopt;
  const glm::dvec3 dp(p);
  SphericalTriangle st(glm::dvec3(light.p0) - dp, glm::dvec3(light.p1) - dp, glm::dvec3(light.p2) - dp);
  const double omega = st.solidAngle();
  if (!(omega >= kMinSolidAngle) || !(omega <= 2.0 * std::numbers::pi - kHemisphereMargin)) return std::nullopt;
  return st;
}

bool EmitterSet::sampledBySolidAngle(const glm::vec3& p, uint32_t mesh, uint32_t triangle) const {
  if (mesh >= triangleIndex_.size() || triangle >= triangleIndex_[mesh].size()) return false;
  const int32_t index = triangleIndex_[mesh][triangle];
  return index >= 0 && solidAngleStrategy(p, triangles_[size_t(index)]).has_value();
}

glm::vec3 EmitterSet::triangleRadiance(const TriangleLight& light, glm::vec2 b, bool frontSide) const {
  if (!frontSide && !light.twoSided) return glm::vec3(0.0f);
  const MeshData& mesh = scene_->meshes[light.mesh];
  const Material& material = scene_->materials[mesh.material];
  glm::vec3 le = material.emission;
  if (material.emissiveTexture >= 0) {
    const auto& uvs = material.texcoordEmissive == 1 ? mesh.uvs1 : mesh.uvs0;
    if (!uvs.empty()) {
      const uint32_t* idx = &mesh.indices[3 * size_t(light.triangle)];
      const glm::vec2 uv = uvs[idx[0]] * (1.0f - b.x - b.y) + uvs[idx[1]] * b.x + uvs[idx[2]] * b.y;
      le *= glm::vec3(scene_->textures[size_t(material.emissiveTexture)].sample(uv));
    }
  }
  return le;
}

std::optional<LightSample> EmitterSet::sample(const glm::vec3& p, float uLight, glm::vec2 u) const {
  if (distribution_.empty()) return std::nullopt;
  float pmf = 0.0f;
  const size_t index = distribution_.sample(uLight, &pmf);
  return sampleChosen(p, index, pmf, u);
}

std::optional<LightSample> EmitterSet::sampleFolded(const glm::vec3& p, glm::vec2 u) const {
  const size_t index = foldedChoice_.sample(u.x, nullptr, &u.x);
  return sampleChosen(p, index, distribution_.pmf(index), u);  // the pmf pdfTriangle uses
}

std::optional<LightSample> EmitterSet::sampleChosen(const glm::vec3& p, size_t index, float pmf, glm::vec2 u) const {
  LightSample s;
  if (index < triangles_.size()) {
    const TriangleLight& light = triangles_[index];
    const float h = planeDistance(p, light);
    if (std::isnan(h)) return std::nullopt;
    // Seen from behind, a one-sided emitter sends nothing: skip the work.
    const bool front = h > 0.0f;
    if (!front && !light.twoSided) return std::nullopt;
    if (const auto st = solidAngleStrategy(p, light)) {
      // Uniform in the solid angle the triangle subtends at p; the point is where that direction
      // meets it.
      const glm::dvec3 w = st->sample(glm::dvec2(u));
      // Distance along w to the triangle's plane, in double: h itself in float would carry an
      // absolute error of the coordinates' rounding, which near the plane is a large share of it.
      const glm::dvec3 n(light.normal), dp(p);
      const double t = glm::dot(n, glm::dvec3(light.p0) - dp) / glm::dot(n, w);
      if (!(t > 0.0) || !std::isfinite(t)) return std::nullopt;
      s.distance = float(t);
      s.wi = glm::vec3(w);  // unit up to rounding
      // Barycentrics only where the radiance varies over the triangle.
      const glm::vec2 b = light.textured ? glm::vec2(rayTriangleBarycentrics(dp, w, light.p0, light.p1, light.p2))
                                         : glm::vec2(1.0f / 3.0f);
      s.radiance = triangleRadiance(light, b, front);
      if (isBlack(s.radiance)) return std::nullopt;
      s.pdf = float(double(pmf) / st->solidAngle());
      s.cosLight = std::abs(glm::dot(light.normal, s.wi));
      s.emissionPdf = emissionPdf(light, pmf, s.cosLight);
      s.emitter = int32_t(index);
      return s;
    }
    return sampleTrianglePoint(p, index, u, pmf);
  }
  if (int(index) == skyIndex_) {
    s.wi = sampleUniformSphere(u);
    s.radiance = sky_;
    s.pdf = pmf * uniformSpherePdf();
    s.emitter = int32_t(index);
    return s;
  }
  return samplePunctual(p, index, pmf);
}

std::optional<LightSample> EmitterSet::samplePunctual(const glm::vec3& p, size_t index, float pmf) const {
  LightSample s;
  s.emitter = int32_t(index);
  // The light path's density is the power choice's, whatever chose the light here.
  const float powerPmf = distribution_.pmf(index);
  const PunctualLight& light = punctual_[index - triangles_.size()];
  s.delta = true;
  s.pdf = pmf;
  if (light.type == LightType::Directional) {
    s.wi = -glm::normalize(light.direction);
    s.radiance = light.intensity;
    s.emissionPdf = powerPmf / (kPi * radius_ * radius_);
    return s;
  }
  const glm::vec3 d = light.position - p;
  const float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.0f)) return std::nullopt;
  s.distance = std::sqrt(dist2);
  s.wi = d / s.distance;
  s.radiance = light.intensity * (spotAttenuation(light, -s.wi) * rangeWindow(light, s.distance) / dist2);
  if (isBlack(s.radiance)) return std::nullopt;
  s.emissionPdf = powerPmf * (light.type == LightType::Spot ? uniformConePdf(Cone::fromCos(light.cosOuter)) : uniformSpherePdf());
  return s;
}

float EmitterSet::pdfTriangle(const glm::vec3& p, const SurfaceHit& hit) const {
  if (hit.mesh >= triangleIndex_.size() || triangleIndex_[hit.mesh].empty()) return 0.0f;
  const int32_t index = triangleIndex_[hit.mesh][hit.triangle];
  if (index < 0) return 0.0f;
  return pdfTrianglePoint(p, size_t(index), hit.position, hit.geometricNormal, hit.frontFace);
}

float EmitterSet::pdfTrianglePoint(const glm::vec3& p, size_t index, const glm::vec3& x, const glm::vec3& normal,
                                   bool front) const {
  const TriangleLight& light = triangles_[index];
  if (!front && !light.twoSided) return 0.0f;
  if (std::isnan(planeDistance(p, light))) return 0.0f;  // sample() sends nothing from there
  if (const auto st = solidAngleStrategy(p, light)) return float(double(distribution_.pmf(index)) / st->solidAngle());
  return areaToSolidAngle(p, index, x, normal, distribution_.pmf(index));
}

int32_t EmitterSet::emitterOf(const SurfaceHit& hit) const {
  if (hit.mesh >= triangleIndex_.size() || triangleIndex_[hit.mesh].empty()) return -1;
  return triangleIndex_[hit.mesh][hit.triangle];
}

glm::vec2 EmitterSet::squareOf(size_t index, const glm::vec3& x) const {
  // Barycentrics of x (in the plane), then sampleUniformTriangle's two affine halves undone.
  const TriangleLight& light = triangles_[index];
  const glm::vec3 e1 = light.p1 - light.p0, e2 = light.p2 - light.p0, d = x - light.p0;
  const float d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
  const float d1 = glm::dot(d, e1), d2 = glm::dot(d, e2);
  const float det = d11 * d22 - d12 * d12;
  const float bx = (d22 * d1 - d12 * d2) / det, by = (d11 * d2 - d12 * d1) / det;
  const float b1 = bx, b0 = 1.0f - bx - by;
  const glm::vec2 s = b0 < b1 ? glm::vec2(2.0f * b0, b0 + b1) : glm::vec2(b0 + b1, 2.0f * b1);
  return glm::clamp(s, glm::vec2(0.0f), glm::vec2(std::nextafter(1.0f, 0.0f)));
}

std::optional<LightSample> EmitterSet::sampleTrianglePoint(const glm::vec3& p, size_t index, glm::vec2 square,
                                                           float choice) const {
  const TriangleLight& light = triangles_[index];
  const glm::vec2 b = sampleUniformTriangle(square);
  const glm::vec3 d = trianglePoint(light, b).position - p;
  const float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.0f)) return std::nullopt;
  LightSample s;
  s.distance = std::sqrt(dist2);
  s.wi = d / s.distance;
  const float cosLight = -glm::dot(light.normal, s.wi);
  if (std::abs(cosLight) < 1e-7f) return std::nullopt;
  s.radiance = triangleRadiance(light, b, cosLight > 0.0f);
  if (isBlack(s.radiance)) return std::nullopt;
  s.pdf = choice * dist2 / (std::abs(cosLight) * light.area);
  s.cosLight = std::abs(cosLight);
  s.emissionPdf = emissionPdf(light, distribution_.pmf(index), s.cosLight);
  s.emitter = int32_t(index);
  return s;
}

std::optional<LightSample> EmitterSet::sampleTriangleByArea(const glm::vec3& p, size_t index, glm::vec2 square,
                                                            float choice) const {
  const TriangleLight& light = triangles_[index];
  const float h = planeDistance(p, light);
  if (std::isnan(h) || (h < 0.0f && !light.twoSided)) return std::nullopt;
  return sampleTrianglePoint(p, index, square, choice);
}

float EmitterSet::areaToSolidAngle(const glm::vec3& p, size_t index, const glm::vec3& x, const glm::vec3& normal,
                                   float choice) const {
  const glm::vec3 d = x - p;
  const float dist2 = glm::dot(d, d);
  const float cosLight = std::abs(glm::dot(normal, d)) / std::sqrt(dist2);
  if (!(cosLight > 1e-7f)) return 0.0f;
  return choice * dist2 / (cosLight * triangles_[index].area);
}

float EmitterSet::solidAnglePdfOfArea(const glm::vec3& p, size_t index, const glm::vec3& x, const glm::vec3& normal,
                                      bool front, float choice) const {
  const TriangleLight& light = triangles_[index];
  if (!front && !light.twoSided) return 0.0f;
  if (std::isnan(planeDistance(p, light))) return 0.0f;
  return areaToSolidAngle(p, index, x, normal, choice);
}

float EmitterSet::emissionPdf(const TriangleLight& light, float pmf, float cosLight) {
  return pmf * cosLight / (kPi * light.area * (light.twoSided ? 2.0f : 1.0f));
}

float EmitterSet::pdfEmission(const SurfaceHit& hit, const glm::vec3& direction) const {
  if (hit.mesh >= triangleIndex_.size() || triangleIndex_[hit.mesh].empty()) return 0.0f;
  const int32_t index = triangleIndex_[hit.mesh][hit.triangle];
  if (index < 0) return 0.0f;
  const TriangleLight& light = triangles_[size_t(index)];
  if (!hit.frontFace && !light.twoSided) return 0.0f;
  return emissionPdf(light, distribution_.pmf(size_t(index)), std::abs(glm::dot(hit.geometricNormal, direction)));
}

float EmitterSet::nextEventPdfTimesCos(const glm::vec3& p, const EmissionSample& e) const {
  const float pmf = distribution_.pmf(e.emitter);
  if (e.emitter < triangles_.size()) {
    const TriangleLight& light = triangles_[e.emitter];
    const glm::vec3 d = p - e.position;
    const float dist = glm::length(d);
    if (!(dist > 0.0f)) return 0.0f;
    const bool front = glm::dot(e.normal, light.normal) > 0.0f;
    return pdfTrianglePoint(p, e.emitter, e.position, light.normal, front) * std::abs(glm::dot(e.normal, d)) / dist;
  }
  if (int(e.emitter) == skyIndex_) return pmf * uniformSpherePdf();
  if (punctual_[e.emitter - triangles_.size()].type == LightType::Directional) return pmf;
  const glm::vec3 d = p - e.position;
  return pmf * glm::dot(d, d);
}

bool EmitterSet::supportsConnections() const {
  if (skyIndex_ >= 0) return false;
  for (const PunctualLight& light : punctual_)
    if (light.range > 0.0f) return false;
  return true;
}

float EmitterSet::pdfSky(const glm::vec3&) const {
  return skyIndex_ < 0 ? 0.0f : distribution_.pmf(size_t(skyIndex_)) * uniformSpherePdf();
}

glm::vec3 EmitterSet::emitted(const SurfaceHit& hit, const glm::vec3&) const {
  if (hit.mesh >= triangleIndex_.size() || triangleIndex_[hit.mesh].empty()) return glm::vec3(0.0f);
  const int32_t index = triangleIndex_[hit.mesh][hit.triangle];
  if (index < 0) return glm::vec3(0.0f);
  const TriangleLight& light = triangles_[size_t(index)];
  const MeshData& mesh = scene_->meshes[light.mesh];
  const Material& material = scene_->materials[mesh.material];
  glm::vec3 le = material.emission;
  if (material.emissiveTexture >= 0) {
    le *= glm::vec3(scene_->textures[size_t(material.emissiveTexture)].sample(material.texcoordEmissive == 1 ? hit.uv1 : hit.uv0));
  }
  return (hit.frontFace || light.twoSided) ? le : glm::vec3(0.0f);
}

std::optional<EmissionSample> EmitterSet::sampleEmission(float uLight, glm::vec2 uPos, glm::vec2 uDir) const {
  if (distribution_.empty()) return std::nullopt;
  float pmf = 0.0f, uSide = 0.0f;
  const size_t index = distribution_.sample(uLight, &pmf, &uSide);
  return sampleEmissionChosen(index, pmf, uSide, uPos, uDir);
}

std::optional<EmissionSample> EmitterSet::sampleEmissionStratified(glm::vec2 uPos, glm::vec2 uDir, float uSpare) const {
  if (!foldsChoice()) return sampleEmission(uSpare, uPos, uDir);
  const size_t index = foldedChoice_.sample(uPos.x, nullptr, &uPos.x);
  return sampleEmissionChosen(index, distribution_.pmf(index), uSpare, uPos, uDir);
}

std::optional<EmissionSample> EmitterSet::sampleEmissionChosen(size_t index, float pmf, float uSide, glm::vec2 uPos,
                                                               glm::vec2 uDir) const {
  EmissionSample e;
  if (index < triangles_.size()) {
    // Position uniform on the triangle, direction cosine-distributed: weight = Le pi area / pmf.
    const TriangleLight& light = triangles_[index];
    const glm::vec2 b = sampleUniformTriangle(uPos);
    const TrianglePoint tp = trianglePoint(light, b);
    glm::vec3 n = tp.normal;
    bool front = true;
    float sides = 1.0f;
    if (light.twoSided) {
      front = uSide < 0.5f;
      sides = 2.0f;
    }
    if (!front) n = -n;
    e.position = tp.position;
    e.normal = n;
    e.direction = Frame::fromNormal(n).toWorld(sampleCosineHemisphere(uDir));
    e.weight = triangleRadiance(light, b, front) * (kPi * light.area * sides / pmf);
    e.pdf = emissionPdf(light, pmf, std::max(0.0f, glm::dot(n, e.direction)));
    e.emitter = uint32_t(index);
    e.square = uPos;
    return e;
  }
  const glm::vec3 travelSky = -sampleUniformSphere(uDir);
  if (int(index) == skyIndex_ || punctual_[index - triangles_.size()].type == LightType::Directional) {
    // Parallel rays through a disk that covers the scene's bounding sphere.
    const bool isSky = int(index) == skyIndex_;
    const glm::vec3 travel = isSky ? travelSky : glm::normalize(punctual_[index - triangles_.size()].direction);
    const glm::vec2 disk = sampleConcentricDisk(uPos) * radius_;
    const Frame frame = Frame::fromNormal(travel);
    e.position = centre_ - travel * radius_ + frame.s * disk.x + frame.t * disk.y;
    e.direction = travel;
    const float diskArea = kPi * radius_ * radius_;
    e.weight = isSky ? sky_ * (diskArea / (pmf * uniformSpherePdf()))
                     : punctual_[index - triangles_.size()].intensity * (diskArea / pmf);
    e.pdf = pmf / diskArea * (isSky ? uniformSpherePdf() : 1.0f);
    e.emitter = uint32_t(index);
    return e;
  }
  const PunctualLight& light = punctual_[index - triangles_.size()];
  e.position = light.position;
  if (light.type == LightType::Spot) {
    // The scene keeps the outer cone as a cosine, so this is the cone of that cosine (exact for it);
    // a cone so narrow that its cosine is 1 has no power above and is never sampled.
    const Cone cone = Cone::fromCos(light.cosOuter);
    e.direction = Frame::fromNormal(glm::normalize(light.direction)).toWorld(sampleUniformCone(uDir, cone));
    e.weight = light.intensity * (spotAttenuation(light, e.direction) / (uniformConePdf(cone) * pmf));
    e.pdf = pmf * uniformConePdf(cone);
  } else {
    e.direction = sampleUniformSphere(uDir);
    e.weight = light.intensity * (1.0f / (uniformSpherePdf() * pmf));
    e.pdf = pmf * uniformSpherePdf();
  }
  e.emitter = uint32_t(index);
  e.deltaPosition = true;
  return e;
}

}  // namespace vpl
