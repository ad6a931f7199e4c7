#include "render/scene/emitters.h"

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
      triangles_.push_back({m, t, area, material.doubleSided});
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
  distribution_ = Distribution1D(power);
}

EmitterSet::TrianglePoint EmitterSet::trianglePoint(const TriangleLight& light, glm::vec2 b) const {
  const MeshData& mesh = scene_->meshes[light.mesh];
  const uint32_t* idx = &mesh.indices[3 * size_t(light.triangle)];
  const glm::vec3 p0 = mesh.positions[idx[0]], p1 = mesh.positions[idx[1]], p2 = mesh.positions[idx[2]];
  return {p0 * (1.0f - b.x - b.y) + p1 * b.x + p2 * b.y, glm::normalize(glm::cross(p1 - p0, p2 - p0))};
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
  LightSample s;
  if (index < triangles_.size()) {
    // Sample an emissive triangle by area, convert the density to solid angle at p.
    const TriangleLight& light = triangles_[index];
    const glm::vec2 b = sampleUniformTriangle(u);
    const TrianglePoint tp = trianglePoint(light, b);
    const glm::vec3 x = tp.position, n = tp.normal;
    const glm::vec3 d = x - p;
    const float dist2 = glm::dot(d, d);
    if (!(dist2 > 0.0f)) return std::nullopt;
    s.distance = std::sqrt(dist2);
    s.wi = d / s.distance;
    const float cosLight = -glm::dot(n, s.wi);
    if (std::abs(cosLight) < 1e-7f) return std::nullopt;
    s.radiance = triangleRadiance(light, b, cosLight > 0.0f);
    if (isBlack(s.radiance)) return std::nullopt;
    s.pdf = pmf * dist2 / (std::abs(cosLight) * light.area);
    return s;
  }
  if (int(index) == skyIndex_) {
    s.wi = sampleUniformSphere(u);
    s.radiance = sky_;
    s.pdf = pmf * uniformSpherePdf();
    return s;
  }
  const PunctualLight& light = punctual_[index - triangles_.size()];
  s.delta = true;
  s.pdf = pmf;
  if (light.type == LightType::Directional) {
    s.wi = -glm::normalize(light.direction);
    s.radiance = light.intensity;
    return s;
  }
  const glm::vec3 d = light.position - p;
  const float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.0f)) return std::nullopt;
  s.distance = std::sqrt(dist2);
  s.wi = d / s.distance;
  s.radiance = light.intensity * (spotAttenuation(light, -s.wi) * rangeWindow(light, s.distance) / dist2);
  if (isBlack(s.radiance)) return std::nullopt;
  return s;
}

float EmitterSet::pdfTriangle(const glm::vec3& p, const SurfaceHit& hit) const {
  if (hit.mesh >= triangleIndex_.size() || triangleIndex_[hit.mesh].empty()) return 0.0f;
  const int32_t index = triangleIndex_[hit.mesh][hit.triangle];
  if (index < 0) return 0.0f;
  const TriangleLight& light = triangles_[size_t(index)];
  const glm::vec3 d = hit.position - p;
  const float dist2 = glm::dot(d, d);
  const float cosLight = std::abs(glm::dot(hit.geometricNormal, d)) / std::sqrt(dist2);
  if (!(cosLight > 1e-7f)) return 0.0f;
  if (!hit.frontFace && !light.twoSided) return 0.0f;
  return distribution_.pmf(size_t(index)) * dist2 / (cosLight * light.area);
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
  } else {
    e.direction = sampleUniformSphere(uDir);
    e.weight = light.intensity * (1.0f / (uniformSpherePdf() * pmf));
  }
  return e;
}

}  // namespace vpl
