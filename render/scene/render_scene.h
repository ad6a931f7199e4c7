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

// spawnShadowRay's aim at a finite distance, for floats or vectors of them (F: the path lanes' eight at
// once; squareRoot(v, r) sets r to v's square root): from origin o, p offset (spawnRay), at the light
// point p + w distance, stopped short by a margin; sets the direction d and tMax. By reference: vectors
// cross no call by value.
template <class F, class SquareRoot>
void aimShadowRay(const F& px, const F& py, const F& pz, const F& ox, const F& oy, const F& oz, const F& wx, const F& wy,
                  const F& wz, const F& distance, F& dx, F& dy, F& dz, F& tMax, SquareRoot squareRoot) {
  // Aimed from the offset origin at the light point itself: a ray parallel to w from there meets a
  // light seen at a grazing angle up to offset / sin(angle) before the point, on the light's own
  // surface (a ceiling 0.15 m above a globe lamp of 528 facets: a fifth of the shadow rays ended on
  // the lamp, the ceiling 3.6 % too dark). Then stop short of the point by a margin that covers both a
  // relative error of the distance and the light's own surface offset (coordinates there are of the
  // same size as here). A margin of the distance alone let rays between close, parallel surfaces far
  // from the origin end on the light itself.
  const F tx = px + wx * distance - ox, ty = py + wy * distance - oy, tz = pz + wz * distance - oz;
  F length, offset;
  squareRoot(tx * tx + ty * ty + tz * tz, length);
  const F ex = ox - px, ey = oy - py, ez = oz - pz;
  squareRoot(ex * ex + ey * ey + ez * ez, offset);
  const auto away = length > 0.0f;  // else tMax 0, along w
  const F safeLength = away ? length : F{} + 1.0f;
  dx = away ? tx / safeLength : wx, dy = away ? ty / safeLength : wy, dz = away ? tz / safeLength : wz;
  const F relative = 1e-4f * distance, twice = 2.0f * offset;
  const F margin = relative < twice ? twice : relative;  // std::max's
  const F left = length - margin;
  tMax = away ? (0.0f < left ? left : F{}) : F{};  // std::max(0, left)'s
}

}  // namespace vpl
