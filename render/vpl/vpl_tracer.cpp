#include "render/vpl/vpl_tracer.h"

#include <algorithm>
#include <tbb/parallel_for.h>
#include "render/core/color.h"
#include "render/sampling/rng.h"
#include "render/vpl/light_walk.h"

namespace vpl {

std::string VplSettings::validate() const {
  if (count < 0 || count > 50'000'000) return "VPL count must be between 0 and 50,000,000";
  if (maxDepth < 0 || maxDepth > 256) return "VPL path depth must be between 0 and 256";
  return {};
}

namespace {

struct PathResult {
  std::vector<Vpl> vpls;
  uint64_t rays = 0;
};

// One light path; VPL fluxes are left un-normalised (divided by the path count at the end).
void traceLightPath(const RenderScene& scene, const VplSettings& settings, uint64_t pathIndex, PathResult& out) {
  // A light path takes an unbounded count of numbers: its own hashed random stream.
  Rng rng = Rng::hashed(mix64(settings.seed ^ 0x5bd1e995ull) ^ pathIndex);
  RandomWalkNumbers numbers{rng};
  const auto emission = startLightPath(scene, numbers);
  if (!emission) return;
  const auto leaveVpl = [&](const LightWalkVertex& v) {
    if (!v.bsdf.isNearSpecular()) {
      Vpl vpl;
      vpl.position = v.surface.position;
      vpl.normal = v.surface.shadingNormal;
      vpl.flux = v.throughput;
      vpl.incident = v.wIn;
      vpl.bsdf = v.bsdf;
      vpl.material = v.surface.material;
      vpl.bounce = uint16_t(std::min(v.length, 65535));
      out.vpls.push_back(vpl);
    }
    return true;
  };
  out.rays += walkLightPath(scene, numbers, *emission, settings.maxDepth, leaveVpl, [](const LightWalkVertex&, const BsdfSample&, float) {});
}

}  // namespace

VplSet traceVpls(const RenderScene& scene, const VplSettings& settings) {
  VplSet set;
  if (settings.count == 0 || settings.maxDepth == 0 || scene.emitters().empty()) return set;
  constexpr uint64_t kBatch = 1024;
  // Batches are traced in parallel and appended in path order: the result is independent of threads.
  while (set.vpls.size() < size_t(settings.count) && set.lightPaths < 64ull * uint64_t(settings.count) + kBatch) {
    std::vector<PathResult> batch(kBatch);
    tbb::parallel_for(uint64_t(0), kBatch, [&](uint64_t i) { traceLightPath(scene, settings, set.lightPaths + i, batch[i]); });
    for (PathResult& r : batch) {
      set.rays += r.rays;
      set.vpls.insert(set.vpls.end(), r.vpls.begin(), r.vpls.end());
    }
    set.lightPaths += kBatch;
  }
  const float inv = 1.0f / float(set.lightPaths);
  for (Vpl& v : set.vpls) v.flux *= inv;
  return set;
}

VplSettings vplSettingsForPaths(VplSettings base, int pathDepth, uint64_t seed) {
  base.maxDepth = std::clamp(pathDepth - 1, 0, 256);
  base.seed = seed;
  return base;
}

glm::vec3 vplContribution(const Vpl& light, const glm::vec3& x, const Bsdf& receiver, const glm::vec3& wo,
                          float minDistance) {
  const glm::vec3 d = light.position - x;
  const float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.0f)) return glm::vec3(0.0f);
  const glm::vec3 toLight = d / std::sqrt(dist2);
  // eval(wo = incident, wi = towards x) carries the cosine at the VPL; the receiver's eval carries its own.
  const glm::vec3 leaving = light.bsdf.eval(light.incident, -toLight);
  const glm::vec3 arriving = receiver.eval(wo, toLight);
  return light.flux * leaving * arriving / std::max(dist2, minDistance * minDistance);
}

}  // namespace vpl
