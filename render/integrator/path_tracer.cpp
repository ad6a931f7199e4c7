#include "render/integrator/path_tracer.h"

#include <algorithm>
#include <cmath>
#include <vector>
#include "render/core/color.h"
#include "render/sampling/warps.h"
#include "render/vpl/irradiance_grid.h"

namespace vpl {

namespace {

// The continuation at a vertex: direction and pdf in `dir`, f cos / pdf in `weight`. False ends the path.
bool sampleContinuation(const SurfaceHit& surface, const Bsdf& bsdf, const glm::vec3& wo, VertexSamples& u,
                        ContinuationSampler& continuation, PathStats& stats, DirectionSample& dir, glm::vec3& weight) {
  if (!continuation.sample(surface, bsdf, wo, u, dir, stats)) return false;
  weight = dir.weight.x >= 0.0f ? dir.weight : bsdf.eval(wo, dir.wi) / dir.pdf;
  return !isBlack(weight) && glm::dot(dir.wi, surface.geometricNormal) > 0.0f;
}

}  // namespace

std::string PathTracerSettings::validate() const {
  if (maxDepth < 1 || maxDepth > 1024) return "max depth must be between 1 and 1024";
  if (rrStartDepth < 1) return "Russian roulette start depth must be at least 1";
  if (std::string e = window.validate(); !e.empty()) return e;
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

PathTracer::PathTracer(const RenderScene& scene, const PathTracerSettings& settings, const IrradianceGrid* irradiance)
    : scene_(scene), settings_(settings) {
  const bool windowRule = settings_.roulette == RouletteRule::Vpl || settings_.roulette == RouletteRule::Auto;
  if (windowRule && irradiance && !irradiance->empty()) irradiance_ = irradiance;
}

float PathTracer::predictedRadiance(const SurfaceHit& surface, const Bsdf& bsdf) const {
  // A diffuse reflector of the BSDF's albedo at normal incidence: rough, but only ever a ratio's input.
  const glm::vec3 albedo = glm::min(bsdf.params().diffuse + bsdf.params().f0, glm::vec3(1.0f));
  return luminance(albedo * irradiance_->irradiance(surface.position, surface.geometricNormal)) * kInvPi;
}

// A path waiting to be traced: a split vertex's other branches, each with its own numbers.
struct PathTracer::Branch {
  Ray ray;
  glm::vec3 beta{1.0f};
  SurfaceHit previous;
  float previousPdf = 0.0f;
  int depth = 0;
  PixelSampler sampler;
};

glm::vec3 PathTracer::radiance(const Ray& cameraRay, PixelSampler& sampler, ContinuationSampler& continuation,
                               PathStats& stats, uint64_t pixel) const {
  const EmitterSet& emitters = scene_.emitters();
  continuation.beginPath(pixel);
  glm::vec3 L(0.0f);
  // The branches still to trace (kept per thread: most samples never split); `path` is being traced.
  static thread_local std::vector<Branch> pending;
  pending.clear();
  int branchesLeft = settings_.window.maxBranches - 1;
  uint32_t nextBranchId = 1;
  float pixelEstimate = 0.0f;  // the weight window's reference, set at the camera ray's hit
  glm::vec3 firstContinuationStart(0.0f);  // L before the first vertex's continuation

  Branch path{cameraRay, glm::vec3(1.0f), SurfaceHit{}, 0.0f, 0, sampler};
  for (;;) {
    Ray& ray = path.ray;
    glm::vec3& beta = path.beta;
    const int depth = path.depth;
    bool ended = true;
    do {
      const RayHit hit = scene_.accel().intersect(ray);
      ++stats.rays;

      // Escaped: the sky, weighted against next-event estimation of the sky.
      if (!hit.valid()) {
        if (emitters.hasSky()) {
          const float w = depth == 0 ? 1.0f : powerHeuristic(path.previousPdf, emitters.pdfSky(ray.direction));
          L += beta * emitters.sky() * w;
        }
        break;
      }
      const SurfaceHit surface = scene_.surface(ray, hit);
      const glm::vec3 wo = -ray.direction;
      continuation.beginVertex(depth);

      // Emitter hit, weighted against next-event estimation of the same triangle.
      const glm::vec3 le = emitters.emitted(surface, wo);
      if (!isBlack(le)) {
        const float w = depth == 0 ? 1.0f : powerHeuristic(path.previousPdf, emitters.pdfTriangle(path.previous.position, surface));
        L += beta * le * w;
      }
      if (depth + 1 > settings_.maxDepth) break;

      const Bsdf bsdf = scene_.bsdf(surface, wo);
      VertexSamples u(path.sampler, depth);

      // The weight window: roulette for paths worth little against the pixel, splitting for those
      // worth much. The camera ray's hit sets the pixel's estimate, its own ratio is 1 by definition.
      int split = 1;
      bool windowed = false;  // the window decided here, so the throughput rule does not
      if (irradiance_) {
        const float predicted = predictedRadiance(surface, bsdf);
        if (depth == 0) {
          pixelEstimate = luminance(le) + predicted;
        } else if (pixelEstimate > 0.0f && predicted > 0.0f) {
          // No VPL near either end means no estimate, not darkness: the throughput rule decides.
          windowed = true;
          const WindowDecision d = weightWindow(luminance(beta) * predicted / pixelEstimate, settings_.window);
          if (d.survival < 1.0f) {
            if (u.roulette() >= d.survival) break;
            beta /= d.survival;
          }
          split = std::min(d.split, branchesLeft + 1);
        }
      }

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

      if (depth == 0) firstContinuationStart = L;

      // The split's other branches first (each its own numbers), then this path's own continuation.
      const glm::vec3 branchBeta = beta / float(split);
      for (int b = 1; b < split; ++b) {
        Branch next{Ray{}, glm::vec3(0.0f), surface, 0.0f, depth + 1, path.sampler.branch(nextBranchId++)};
        VertexSamples ub(next.sampler, depth);
        DirectionSample dir;
        glm::vec3 weight;
        if (!sampleContinuation(surface, bsdf, wo, ub, continuation, stats, dir, weight)) continue;
        next.beta = branchBeta * weight;
        if (!isFiniteNonNegative(next.beta)) continue;
        next.ray = spawnRay(surface, dir.wi);
        next.previousPdf = dir.pdf;
        pending.push_back(next);
        --branchesLeft;
        ++stats.branches;
      }
      beta = branchBeta;

      // Continuation direction.
      DirectionSample next;
      glm::vec3 weight;
      if (!sampleContinuation(surface, bsdf, wo, u, continuation, stats, next, weight)) break;
      beta *= weight;
      if (!isFiniteNonNegative(beta)) break;

      // Russian roulette on the throughput (after a few bounces, so short paths keep full weight).
      if (!windowed && depth + 1 >= settings_.rrStartDepth) {
        const float t = maxComponent(beta);
        const float survive = std::min(1.0f, settings_.roulette == RouletteRule::Throughput ? t : std::sqrt(t));
        if (u.roulette() >= survive) break;
        beta /= survive;
      }
      path.previous = surface;
      path.previousPdf = next.pdf;
      ray = spawnRay(surface, next.wi);
      path.depth = depth + 1;
      ended = false;
    } while (false);
    if (!ended) continue;
    if (pending.empty()) break;
    path = pending.back();
    pending.pop_back();
  }
  continuation.endPath(L - firstContinuationStart);
  return L;
}

}  // namespace vpl
