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
  const glm::vec3& p = from.position;
  aimShadowRay(p.x, p.y, p.z, r.origin.x, r.origin.y, r.origin.z, wi.x, wi.y, wi.z, distance, r.direction.x,
               r.direction.y, r.direction.z, r.tMax, [](float v, float& root) { root = std::sqrt(v); });
  return r;
}

}  // namespace vpl
