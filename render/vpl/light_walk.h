// A light path's random walk from the emitters, shared by instant radiosity's VPLs
// (render/vpl/vpl_tracer.h) and the light vertices that camera paths join
// (render/integrator/light_vertex_cache.h): where the path starts, how it scatters, when it ends.
//
// The walk scatters by BSDF sampling, reflection only as on the camera side, and carries light's
// flow the other way: with shading normals the adjoint BSDF's weight is f |Ns.wIn| / pdf times
// |Ng.wOut| / |Ns.wOut| over |Ng.wIn| (Veach 1997, §5.3). Russian roulette keeps the throughput at or
// below where it started, so no vertex carries more flux than the emission gave its path.
#pragma once
#include <algorithm>
#include <cstdint>
#include <optional>
#include "render/core/color.h"
#include "render/sampling/pixel_sampler.h"
#include "render/sampling/rng.h"
#include "render/scene/render_scene.h"

namespace vpl {

// One vertex of the walk: where it is, what arrives there, and how.
struct LightWalkVertex {
  const SurfaceHit& surface;
  const Bsdf& bsdf;            // bound to wIn
  glm::vec3 wIn;               // towards where the light came from
  glm::vec3 throughput;        // flux arriving, as summed over paths / path count
  float distance;              // of the segment that arrived
  int length;                  // segments from the emitter, 1 at the first surface
};

// Where a walk's numbers come from: RandomWalkNumbers draws each from one random stream, in the
// order the walk asks; StratifiedWalkNumbers gives path i of a batch the i-th point of an
// Owen-scrambled Sobol sequence in every decision (PixelSampler's slots, the path index as the
// sample index), so that a batch's paths spread over the emitters and their directions as a
// pixel's samples spread over the pixel.
struct RandomWalkNumbers {
  Rng& rng;
  float choice() { return rng.uniform(); }
  glm::vec2 position() { return rng.uniform2(); }
  glm::vec2 direction() { return rng.uniform2(); }
  glm::vec2 scatter(int) { return rng.uniform2(); }
  float roulette(int) { return rng.uniform(); }
};
struct StratifiedWalkNumbers {
  PixelSampler sampler;  // vertex 0: the start; vertex k: the scattering at the k-th surface
  float choice() { return sampler.get1D(0, VertexDimension::LightChoiceRoulette); }
  glm::vec2 position() { return sampler.get2D(0, VertexDimension::LightPoint); }
  glm::vec2 direction() { return sampler.get2D(0, VertexDimension::BsdfDirection); }
  glm::vec2 scatter(int length) { return sampler.get2D(length, VertexDimension::BsdfDirection); }
  float roulette(int length) { return sampler.getPair(length, VertexDimension::LightChoiceRoulette).y(); }
};

// The path's start; empty when the emitters send nothing.
template <class Numbers>
std::optional<EmissionSample> startLightPath(const RenderScene& scene, Numbers& numbers) {
  const float uLight = numbers.choice();
  const glm::vec2 uPos = numbers.position(), uDir = numbers.direction();
  auto e = scene.emitters().sampleEmissionStratified(uPos, uDir, uLight);
  if (!e || !(e->pdf > 0.0f) || !isFiniteNonNegative(e->weight) || isBlack(e->weight)) return std::nullopt;
  return e;
}

// Walks from `start` for at most maxLength segments. onVertex(const LightWalkVertex&) is called at
// every surface reached and returns false to end the walk there; onScatter(const LightWalkVertex&,
// const BsdfSample&, float cosOut) at every vertex the walk leaves, before roulette (cosOut: the
// sampled direction's cosine to the geometric normal). Returns the rays traced.
template <class Numbers, class OnVertex, class OnScatter>
uint64_t walkLightPath(const RenderScene& scene, Numbers& numbers, const EmissionSample& start, int maxLength,
                       OnVertex&& onVertex, OnScatter&& onScatter) {
  uint64_t rays = 0;
  glm::vec3 throughput = start.weight;
  const float startMax = maxComponent(start.weight);
  const bool onSurface = start.normal != glm::vec3(0.0f);
  Ray ray;
  ray.origin = onSurface ? offsetRayOrigin(start.position, start.normal, scene.coordinateScale()) : start.position;
  ray.direction = start.direction;
  for (int length = 1; length <= maxLength; ++length) {
    const RayHit hit = scene.accel().intersect(ray);
    ++rays;
    if (!hit.valid()) break;
    const SurfaceHit surface = scene.surface(ray, hit);
    const glm::vec3 wIn = -ray.direction;
    const float cosIn = std::abs(glm::dot(surface.geometricNormal, wIn));
    if (!(cosIn > 0.0f)) break;
    const Bsdf bsdf = scene.bsdf(surface, wIn);
    const LightWalkVertex vertex{surface, bsdf, wIn, throughput, hit.t, length};
    if (!onVertex(vertex) || length == maxLength) break;

    const auto s = bsdf.sample(wIn, numbers.scatter(length));
    if (!s || !(s->pdf > 0.0f)) break;
    const float cosOut = glm::dot(surface.geometricNormal, s->wi);
    if (!(cosOut > 0.0f)) break;
    const float nsIn = std::abs(glm::dot(surface.shadingNormal, wIn)), nsOut = std::abs(glm::dot(surface.shadingNormal, s->wi));
    if (!(nsOut > 0.0f)) break;
    onScatter(vertex, *s, cosOut);
    throughput *= s->weight * (nsIn * cosOut / (nsOut * cosIn));
    const float survive = std::min(1.0f, maxComponent(throughput) / std::max(1e-30f, startMax));
    if (numbers.roulette(length) >= survive) break;
    throughput /= survive;
    if (!isFiniteNonNegative(throughput)) break;
    ray = spawnRay(surface, s->wi);
  }
  return rays;
}

}  // namespace vpl
