#include "render/integrator/light_vertex_cache.h"

#include <algorithm>
#include <cmath>
#include <tbb/parallel_for.h>
#include "render/core/color.h"
#include "render/sampling/rng.h"
#include "render/vpl/light_walk.h"

namespace vpl {

int ConnectionSettings::pathsFor(int pixels, SamplingMode mode) const {
  if (mode == SamplingMode::Preview) return 0;  // no path tracing to join
  if (paths >= 0) return paths;
  if (!isGuided(mode)) return 0;
  return std::clamp(pixels / 32, 1024, 8192);
}

std::string ConnectionSettings::validate() const {
  if (paths < -1 || paths > 16'777'216) return "connection paths must be -1 (auto), 0 (off) or up to 16,777,216";
  return {};
}

namespace {

struct PathVertices {
  std::vector<LightVertex> vertices;
  uint64_t rays = 0;
};

void traceLightSubpath(const RenderScene& scene, uint64_t key, int maxLength, PathVertices& out) {
  Rng rng = Rng::hashed(key);
  const auto e = startLightPath(scene, rng);
  if (!e) return;
  // A light that no ray can hit (a point, a direction) has no strategy that reaches its start by
  // BSDF sampling: dVC starts at 0.
  float dVC = e->normal != glm::vec3(0.0f) ? connectionMis(glm::dot(e->normal, e->direction) / e->pdf) : 0.0f;
  float dVCM = 0.0f;
  const auto onVertex = [&](const LightWalkVertex& v) {
    const float cosIn = std::abs(glm::dot(v.surface.geometricNormal, v.wIn));
    if (v.length == 1) {
      // Next-event estimation from here would have picked the start with a density of its own.
      dVCM = connectionMis(scene.emitters().nextEventPdfTimesCos(v.surface.position, *e) / (e->pdf * cosIn));
    } else {
      dVCM *= connectionMis(v.distance * v.distance) / connectionMis(cosIn);
    }
    dVC /= connectionMis(cosIn);
    out.vertices.push_back({v.surface.position, v.surface.geometricNormal, v.wIn, v.throughput / cosIn, dVC, dVCM, v.length, v.bsdf});
    return true;
  };
  // Roulette is not counted in the MIS weights: they sum to 1 whatever it does.
  const auto onScatter = [&](const LightWalkVertex& v, const BsdfSample& s, float cosOut) {
    dVC = connectionMis(cosOut / s.pdf) * (dVC * connectionMis(v.bsdf.pdf(s.wi, v.wIn)) + dVCM);
    dVCM = connectionMis(1.0f / s.pdf);
  };
  out.rays += walkLightPath(scene, rng, *e, maxLength, onVertex, onScatter);
}

}  // namespace

void LightVertexCache::build(const RenderScene& scene, uint64_t seed, uint64_t pass, int paths, int maxLength) {
  vertices_.clear();
  paths_ = paths;
  rays_ = 0;
  scale_ = 0.0f;
  // No vertices where the tracer could not weight its joins (PathTracer ignores the cache there).
  if (paths <= 0 || maxLength <= 0 || !scene.emitters().supportsConnections() || scene.emitters().empty()) return;
  constexpr int kBatch = 256;
  const int batches = (paths + kBatch - 1) / kBatch;
  std::vector<PathVertices> results(static_cast<size_t>(batches));
  const uint64_t passKey = mix64(mix64(seed ^ 0x6c76635f70617468ull) ^ pass);
  // Batches in parallel, appended in path order: the cache is the same for any thread count.
  tbb::parallel_for(0, batches, [&](int b) {
    const int end = std::min(paths, (b + 1) * kBatch);
    for (int i = b * kBatch; i < end; ++i) traceLightSubpath(scene, mix64(passKey ^ uint64_t(i)), maxLength, results[size_t(b)]);
  });
  size_t total = 0;
  for (const PathVertices& r : results) total += r.vertices.size();
  vertices_.reserve(total);
  for (PathVertices& r : results) {
    vertices_.insert(vertices_.end(), r.vertices.begin(), r.vertices.end());
    rays_ += r.rays;
  }
  scale_ = float(vertices_.size()) / float(paths_);
}

}  // namespace vpl
