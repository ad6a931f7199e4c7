#include "render/guide/guide_builder.h"

#include <tbb/parallel_for.h>
#include "render/core/color.h"

namespace vpl {

std::optional<VplArrival> vplArrival(const Vpl& light, const SurfaceHit& at, float minDistance) {
  const glm::vec3 d = light.position - at.position;
  const float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.0f)) return std::nullopt;
  VplArrival a;
  a.distance = std::sqrt(dist2);
  a.direction = d / a.distance;
  const float cosReceiver = glm::dot(a.direction, at.shadingNormal);
  if (cosReceiver <= 0.0f || glm::dot(a.direction, at.geometricNormal) <= 0.0f) return std::nullopt;
  a.weight = luminance(light.bsdf.eval(light.incident, -a.direction) * light.flux) * cosReceiver /
             std::max(dist2, minDistance * minDistance);
  if (!(a.weight > 0.0f) || !std::isfinite(a.weight)) return std::nullopt;
  return a;
}

GuideField buildGuideField(const RenderScene& scene, const VplField& field, const GuideSettings& settings) {
  const size_t sliceCount = field.tree.slices.size();
  std::vector<CachePoint> points(sliceCount);
  const float minRadius = 1e-3f * scene.radius();
  tbb::parallel_for(size_t(0), sliceCount, [&](size_t s) {
    const Slice& slice = field.tree.slices[s];
    const SurfaceHit& hit = field.gather.hits[slice.representative];
    CachePoint& cp = points[s];
    cp.position = hit.position;
    cp.normal = hit.shadingNormal;
    float radius = minRadius;
    for (uint32_t i = slice.begin; i < slice.end; ++i)
      radius = std::max(radius, glm::distance(field.gather.points[field.tree.order[i]].position, cp.position));
    cp.radius = radius;

    std::vector<GuideRepresentative> reps;
    const auto& clusters = field.clusters.slices[s].clusters;
    reps.reserve(clusters.size());
    for (const VplCluster& c : clusters) {
      const Vpl& light = field.vpls->vpls[c.representative];
      const float repPower = light.power();
      if (!(repPower > 0.0f)) continue;
      const auto arrival = vplArrival(light, hit, field.minDistance);
      if (!arrival) continue;
      const float weight = arrival->weight * (c.totalPower / repPower);  // the whole cluster's
      if (!(weight > 0.0f) || !std::isfinite(weight)) continue;
      if (scene.accel().occluded(spawnShadowRay(hit, arrival->direction, arrival->distance))) continue;
      // A cluster seen under a wide angle (near, or large) spreads over the angle it subtends.
      reps.push_back({arrival->direction, weight, std::atan2(settings.spreadScale * c.spread, arrival->distance)});
    }
    cp.distribution = GuideDistribution(std::move(reps), settings.coneAngle, settings.defensive, settings.bilinear);
  });
  GuideField guide(std::move(points), settings);
  std::vector<int32_t> perPixel(field.gather.pixelGather.size(), -1);
  for (size_t px = 0; px < perPixel.size(); ++px)
    if (field.gather.pixelGather[px] >= 0) perPixel[px] = int32_t(field.tree.sliceOf[size_t(field.gather.pixelGather[px])]);
  guide.setPixelCachePoints(std::move(perPixel));
  return guide;
}

}  // namespace vpl
