#include "render/integrator/path_tracer.h"

#include <algorithm>
#include <cmath>
#include "render/core/color.h"

namespace vpl {

std::string PathTracerSettings::validate() const {
  if (maxDepth < 1 || maxDepth > 1024) return "max depth must be between 1 and 1024";
  if (rrStartDepth < 1) return "Russian roulette start depth must be at least 1";
  return {};
}

bool BsdfContinuation::sample(const SurfaceHit&, const Bsdf& bsdf, const glm::vec3& wo, VertexSamples& u,
                              DirectionSample& out, PathStats& stats) {
  const auto s = bsdf.sample(wo, u.bsdfDirection());
  if (!s || !(s->pdf > 0.0f)) return false;
  ++stats.bsdfSamples;
  out.wi = s->wi;
  out.pdf = s->pdf;
  out.weight = s->weight;
  return true;
}

float BsdfContinuation::pdf(const SurfaceHit&, const Bsdf& bsdf, const glm::vec3& wo, const glm::vec3& wi) {
  return bsdf.pdf(wo, wi);
}

glm::vec3 PathTracer::radiance(const Ray& cameraRay, PixelSampler& sampler, ContinuationSampler& continuation,
                               PathStats& stats, uint64_t pixel) const {
  const EmitterSet& emitters = scene_.emitters();
  continuation.beginPath(pixel);
  glm::vec3 L(0.0f), beta(1.0f);
  Ray ray = cameraRay;
  SurfaceHit previous;
  float previousPdf = 0.0f;  // continuation pdf of the direction that led here; 0 before the first bounce

  for (int depth = 0;; ++depth) {
    const RayHit hit = scene_.accel().intersect(ray);
    ++stats.rays;

    // Escaped: the sky, weighted against next-event estimation of the sky.
    if (!hit.valid()) {
      if (emitters.hasSky()) {
        const float w = depth == 0 ? 1.0f : powerHeuristic(previousPdf, emitters.pdfSky(ray.direction));
        L += beta * emitters.sky() * w;
      }
      break;
    }
    const SurfaceHit surface = scene_.surface(ray, hit);
    const glm::vec3 wo = -ray.direction;

    // Emitter hit, weighted against next-event estimation of the same triangle.
    const glm::vec3 le = emitters.emitted(surface, wo);
    if (!isBlack(le)) {
      const float w = depth == 0 ? 1.0f : powerHeuristic(previousPdf, emitters.pdfTriangle(previous.position, surface));
      L += beta * le * w;
    }
    if (depth + 1 > settings_.maxDepth) break;

    const Bsdf bsdf = scene_.bsdf(surface);
    VertexSamples u(sampler, depth);

    // Next-event estimation: one light sample, MIS with the continuation strategy.
    if (const auto ls = emitters.sample(surface.position, u.lightChoice(), u.lightPoint())) {
      const glm::vec3 f = bsdf.eval(wo, ls->wi);
      if (!isBlack(f) && glm::dot(ls->wi, surface.geometricNormal) > 0.0f) {
        ++stats.rays;
        if (!scene_.accel().occluded(spawnShadowRay(surface, ls->wi, ls->distance))) {
          const float w = ls->delta ? 1.0f : powerHeuristic(ls->pdf, continuation.pdf(surface, bsdf, wo, ls->wi));
          L += beta * f * ls->radiance * (w / ls->pdf);
        }
      }
    }

    // Continuation direction.
    DirectionSample next;
    if (!continuation.sample(surface, bsdf, wo, u, next, stats)) break;
    const glm::vec3 weight = next.weight.x >= 0.0f ? next.weight : bsdf.eval(wo, next.wi) / next.pdf;
    if (isBlack(weight) || glm::dot(next.wi, surface.geometricNormal) <= 0.0f) break;
    beta *= weight;
    if (!isFiniteNonNegative(beta)) break;

    // Russian roulette on the throughput (after a few bounces, so short paths keep full weight).
    if (depth + 1 >= settings_.rrStartDepth) {
      const float t = maxComponent(beta);
      const float survive = std::min(1.0f, settings_.roulette == RouletteRule::Sqrt ? std::sqrt(t) : t);
      if (u.roulette() >= survive) break;
      beta /= survive;
    }
    previous = surface;
    previousPdf = next.pdf;
    ray = spawnRay(surface, next.wi);
  }
  return L;
}

}  // namespace vpl
