#include "render/integrator/light_vertex_cache.h"

#include <algorithm>
#include <cmath>
#include <tbb/parallel_for.h>
#include "render/core/color.h"
#include "render/sampling/rng.h"

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
  const float uLight = rng.uniform();
  const glm::vec2 uPos = rng.uniform2(), uDir = rng.uniform2();
  const auto e = scene.emitters().sampleEmission(uLight, uPos, uDir);
  if (!e || !(e->pdf > 0.0f) || !isFiniteNonNegative(e->weight) || isBlack(e->weight)) return;
  const bool onSurface = e->normal != glm::vec3(0.0f);
  // A light that no ray can hit (a point, a direction) has no strategy that reaches its start by
  // BSDF sampling: dVC starts at 0.
  float dVC = onSurface ? connectionMis(glm::dot(e->normal, e->direction) / e->pdf) : 0.0f;
  float dVCM = 0.0f;
  glm::vec3 throughput = e->weight;
  const float startMax = maxComponent(e->weight);

  Ray ray;
  ray.origin = onSurface ? offsetRayOrigin(e->position, e->normal, scene.coordinateScale()) : e->position;
  ray.direction = e->direction;
  for (int length = 1; length <= maxLength; ++length) {
    const RayHit hit = scene.accel().intersect(ray);
    ++out.rays;
    if (!hit.valid()) break;
    const SurfaceHit surface = scene.surface(ray, hit);
    const glm::vec3 wIn = -ray.direction;
    const float cosIn = std::abs(glm::dot(surface.geometricNormal, wIn));
    if (!(cosIn > 0.0f)) break;
    if (length == 1) {
      // Next-event estimation from here would have picked the start with a density of its own.
      dVCM = connectionMis(scene.emitters().nextEventPdfTimesCos(surface.position, *e) / (e->pdf * cosIn));
    } else {
      dVCM *= connectionMis(hit.t * hit.t) / connectionMis(cosIn);
    }
    dVC /= connectionMis(cosIn);
    const Bsdf bsdf = scene.bsdf(surface, wIn);
    out.vertices.push_back({surface.position, surface.geometricNormal, wIn, throughput / cosIn, dVC, dVCM, length, bsdf});
    if (length == maxLength) break;

    const auto s = bsdf.sample(wIn, rng.uniform2());
    if (!s || !(s->pdf > 0.0f)) break;
    const float cosOut = glm::dot(surface.geometricNormal, s->wi);
    if (!(cosOut > 0.0f)) break;  // reflection only, as the camera side
    // weight = f |Ns.wOut| / pdf; light flows the other way, so its shading-normal cosine is the
    // arriving one (Veach 1997, §5.3: the adjoint BSDF with shading normals).
    const float nsIn = std::abs(glm::dot(surface.shadingNormal, wIn)), nsOut = std::abs(glm::dot(surface.shadingNormal, s->wi));
    if (!(nsOut > 0.0f)) break;
    throughput *= s->weight * (nsIn * cosOut / (nsOut * cosIn));
    const float reversePdf = bsdf.pdf(s->wi, wIn);
    dVC = connectionMis(cosOut / s->pdf) * (dVC * connectionMis(reversePdf) + dVCM);
    dVCM = connectionMis(1.0f / s->pdf);
    // Russian roulette keeps the throughput near where it started (not counted in the MIS weights:
    // they sum to 1 whatever it does).
    const float survive = std::min(1.0f, maxComponent(throughput) / std::max(1e-30f, startMax));
    if (rng.uniform() >= survive) break;
    throughput /= survive;
    if (!isFiniteNonNegative(throughput)) break;
    ray = spawnRay(surface, s->wi);
  }
}

}  // namespace

void LightVertexCache::build(const RenderScene& scene, uint64_t seed, uint64_t pass, int paths, int maxLength) {
  vertices_.clear();
  paths_ = paths;
  rays_ = 0;
  scale_ = 0.0f;
  if (paths <= 0 || maxLength <= 0 || scene.emitters().empty()) return;
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
