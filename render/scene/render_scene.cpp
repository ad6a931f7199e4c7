#include "render/scene/render_scene.h"

#include <algorithm>
#include <cmath>
#include "render/core/color.h"

namespace vpl {

RenderScene::RenderScene(SceneData data, const SkySettings& sky) : data_(std::move(data)) {
  centre_ = 0.5f * (data_.boundsMin + data_.boundsMax);
  radius_ = 0.5f * glm::length(data_.boundsMax - data_.boundsMin);
  if (!(radius_ > 0.0f) || !std::isfinite(radius_)) radius_ = 1.0f;
  if (data_.materials.empty()) data_.materials.push_back(Material{});
  for (const Material& m : data_.materials) {
    const bool textured = m.baseColorTexture >= 0 || m.metallicRoughnessTexture >= 0;
    uniformBsdfs_.push_back(textured ? std::nullopt : std::optional<Bsdf>(Bsdf(bsdfParams(m, {}), Frame{})));
  }
  accel_ = std::make_unique<Accel>(data_);
  triangles_.reserve(data_.meshes.size());
  for (const MeshData& mesh : data_.meshes) {
    std::vector<TriangleFacts>& facts = triangles_.emplace_back(mesh.indices.size() / 3);
    for (size_t t = 0; t < facts.size(); ++t) {
      const uint32_t* idx = &mesh.indices[3 * t];
      const glm::vec3 p0 = mesh.positions[idx[0]], p1 = mesh.positions[idx[1]], p2 = mesh.positions[idx[2]];
      const glm::vec3 magnitude = glm::max(glm::abs(p0), glm::max(glm::abs(p1), glm::abs(p2)));
      facts[t].coordinateScale = std::max(magnitude.x, std::max(magnitude.y, magnitude.z));
      const glm::vec3 ng = glm::cross(p1 - p0, p2 - p0);
      const float len = glm::length(ng);
      if (len > 0.0f) facts[t].normal = ng / len;
    }
  }

  bool hasLight = !data_.lights.empty();
  for (const MeshData& mesh : data_.meshes) hasLight = hasLight || data_.materials[mesh.material].isEmissive();
  glm::vec3 skyRadiance(0.0f);
  if (sky.explicitSky) {
    skyRadiance = sky.radiance;
  } else if (!hasLight) {
    skyRadiance = sky.radiance;
    defaultSky_ = true;
  }
  emitters_ = EmitterSet(data_, skyRadiance, centre_, radius_);
}

SurfaceHit RenderScene::surface(const Ray& ray, const RayHit& hit) const {
  SurfaceHit s;
  const MeshData& mesh = data_.meshes[hit.mesh];
  const uint32_t* idx = &mesh.indices[3 * size_t(hit.triangle)];
  const glm::vec3 p0 = mesh.positions[idx[0]], p1 = mesh.positions[idx[1]], p2 = mesh.positions[idx[2]];
  const float b0 = 1.0f - hit.u - hit.v;
  s.mesh = hit.mesh;
  s.triangle = hit.triangle;
  s.material = mesh.material;
  // Barycentric interpolation is more precise than origin + t * direction far from the origin.
  s.position = p0 * b0 + p1 * hit.u + p2 * hit.v;
  const TriangleFacts& facts = triangles_[hit.mesh][hit.triangle];
  s.coordinateScale = facts.coordinateScale;

  glm::vec3 ng = facts.normal;
  if (ng == glm::vec3(0.0f)) ng = -ray.direction;  // degenerate: Embree should not report it, but be safe
  s.frontFace = glm::dot(ng, ray.direction) < 0.0f;
  if (!s.frontFace) ng = -ng;  // shade the side the ray came from (two-sided shading)
  s.geometricNormal = ng;

  glm::vec3 ns = ng;
  if (!mesh.normals.empty()) {
    const glm::vec3 n = mesh.normals[idx[0]] * b0 + mesh.normals[idx[1]] * hit.u + mesh.normals[idx[2]] * hit.v;
    const float nlen = glm::length(n);
    if (nlen > 1e-8f && std::isfinite(nlen)) {
      ns = n / nlen;
      if (glm::dot(ns, ng) < 0.0f) ns = -ns;
    }
  }
  s.shadingNormal = ns;
  if (!mesh.uvs0.empty()) s.uv0 = mesh.uvs0[idx[0]] * b0 + mesh.uvs0[idx[1]] * hit.u + mesh.uvs0[idx[2]] * hit.v;
  if (!mesh.uvs1.empty()) s.uv1 = mesh.uvs1[idx[0]] * b0 + mesh.uvs1[idx[1]] * hit.u + mesh.uvs1[idx[2]] * hit.v;
  return s;
}

BsdfParams RenderScene::bsdfParams(const SurfaceHit& hit) const {
  const std::optional<Bsdf>& uniform = uniformBsdfs_[hit.material];
  return uniform ? uniform->params() : bsdfParams(data_.materials[hit.material], hit);
}

BsdfParams RenderScene::bsdfParams(const Material& m, const SurfaceHit& hit) const {
  glm::vec3 baseColor = m.baseColor;
  float metallic = m.metallic, roughness = m.roughness;
  if (m.baseColorTexture >= 0)
    baseColor *= glm::vec3(data_.textures[size_t(m.baseColorTexture)].sample(m.texcoordBaseColor == 1 ? hit.uv1 : hit.uv0));
  if (m.metallicRoughnessTexture >= 0) {
    const glm::vec4 mr = data_.textures[size_t(m.metallicRoughnessTexture)].sample(
        m.texcoordMetallicRoughness == 1 ? hit.uv1 : hit.uv0);
    roughness *= mr.y;
    metallic *= mr.z;
  }
  metallic = glm::clamp(metallic, 0.0f, 1.0f);
  roughness = glm::clamp(roughness, 0.0f, 1.0f);
  baseColor = glm::clamp(baseColor, glm::vec3(0.0f), glm::vec3(1.0f));
  BsdfParams p;
  p.diffuse = baseColor * (1.0f - metallic);
  p.f0 = fresnelF0(baseColor, metallic, m.ior, m.specularFactor, m.specularColor);
  p.f90 = fresnelF90(metallic, m.specularFactor);
  p.alpha = std::max(roughness * roughness, Bsdf::kMinAlpha);
  return p;
}

Ray spawnRay(const SurfaceHit& from, const glm::vec3& wi) {
  Ray r;
  const glm::vec3 n = glm::dot(wi, from.geometricNormal) >= 0.0f ? from.geometricNormal : -from.geometricNormal;
  r.origin = offsetRayOrigin(from.position, n, from.coordinateScale);
  r.direction = wi;
  return r;
}

Ray spawnShadowRay(const SurfaceHit& from, const glm::vec3& wi, float distance) {
  Ray r = spawnRay(from, wi);
  if (!std::isfinite(distance)) return r;
  // Aimed from the offset origin at the light point itself: a ray parallel to wi from there meets a
  // light seen at a grazing angle up to offset / sin(angle) before the point, on the light's own
  // surface (a ceiling 0.15 m above a globe lamp of 528 facets: a fifth of the shadow rays ended on
  // the lamp, the ceiling 3.6 % too dark). Then stop short of the point by a margin that covers both a
  // relative error of the distance and the light's own surface offset (coordinates there are of the
  // same size as here). A margin of the distance alone let rays between close, parallel surfaces far
  // from the origin end on the light itself.
  const glm::vec3 toTarget = from.position + wi * distance - r.origin;
  const float length = glm::length(toTarget);
  if (!(length > 0.0f)) {
    r.tMax = 0.0f;
    return r;
  }
  r.direction = toTarget / length;
  const float offset = glm::length(r.origin - from.position);
  const float margin = std::max(1e-4f * distance, 2.0f * offset);
  r.tMax = std::max(0.0f, length - margin);
  return r;
}

}  // namespace vpl
