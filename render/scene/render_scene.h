// The immutable snapshot the renderer works on: scene data, its Embree BVH, its emitters, and the
// conversion of a ray hit into a shading point. Built once per loaded scene; shared by all threads.
#pragma once
#include <algorithm>
#include <memory>
#include <optional>
#include <vector>
#include <glm/glm.hpp>
#include "render/material/bsdf.h"
#include "render/scene/accel.h"
#include "render/scene/emitters.h"
#include "render/scene/scene_data.h"
#include "render/scene/surface.h"

namespace vpl {

struct SkySettings {
  // Unset: a uniform white sky only when the scene has no light at all.
  bool explicitSky = false;
  glm::vec3 radiance{1.0f};
};

class RenderScene {
 public:
  RenderScene(SceneData data, const SkySettings& sky = {});

  const SceneData& data() const { return data_; }
  const Accel& accel() const { return *accel_; }
  const EmitterSet& emitters() const { return emitters_; }
  glm::vec3 centre() const { return centre_; }
  float radius() const { return radius_; }
  // Largest |coordinate| of the scene bounds: the rounding scale of points with no triangle at hand.
  float coordinateScale() const {
    const glm::vec3 m = glm::max(glm::abs(data_.boundsMin), glm::abs(data_.boundsMax));
    return std::max(m.x, std::max(m.y, m.z));
  }
  // True when the sky was switched on because the scene has no light (the CLI prints a notice).
  bool usesDefaultSky() const { return defaultSky_; }

  // What a hit needs of its triangle that no ray changes: made once, read at every hit.
  struct TriangleFacts {
    glm::vec3 normal{0.0f};  // unit winding normal; zero for a degenerate triangle
    float coordinateScale = 1.0f;
  };
  const TriangleFacts& triangleFacts(uint32_t mesh, uint32_t triangle) const { return triangles_[mesh][triangle]; }

  // Shading point of a hit; wo is the unit direction back along the ray.
  SurfaceHit surface(const Ray& ray, const RayHit& hit) const;
  // BSDF parameters at a hit: texture lookups only for textured materials.
  BsdfParams bsdfParams(const SurfaceHit& hit) const;
  Bsdf bsdf(const SurfaceHit& hit) const {
    const Frame frame = Frame::fromNormal(hit.shadingNormal);
    const std::optional<Bsdf>& uniform = uniformBsdfs_[hit.material];
    return uniform ? uniform->inFrame(frame) : Bsdf(bsdfParams(hit), frame);
  }
  // The BSDF of a path vertex, bound to the direction the path arrived from (Bsdf::bindOutgoing).
  Bsdf bsdf(const SurfaceHit& hit, const glm::vec3& wo) const {
    Bsdf b = bsdf(hit);
    b.bindOutgoing(wo);
    return b;
  }

 private:
  BsdfParams bsdfParams(const Material& material, const SurfaceHit& hit) const;

  SceneData data_;
  std::vector<std::vector<TriangleFacts>> triangles_;  // per mesh, per triangle
  // Per material, its BSDF when no texture varies it over the surface (made once, placed per hit).
  std::vector<std::optional<Bsdf>> uniformBsdfs_;
  std::unique_ptr<Accel> accel_;
  EmitterSet emitters_;
  glm::vec3 centre_{0.0f};
  float radius_ = 1.0f;
  bool defaultSky_ = false;
};

// A ray leaving a surface towards wi, offset to avoid re-hitting it.
Ray spawnRay(const SurfaceHit& from, const glm::vec3& wi);
// A shadow ray from a surface towards a point at distance (INFINITY: towards a direction).
Ray spawnShadowRay(const SurfaceHit& from, const glm::vec3& wi, float distance);

}  // namespace vpl
