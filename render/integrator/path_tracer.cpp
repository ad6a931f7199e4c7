#include "render/integrator/path_tracer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>
#include "render/core/color.h"
#include "render/guide/emitter_guide.h"
#include "render/integrator/light_vertex_cache.h"
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

// 1 / (1 + the other strategies' weights over this one's): the bidirectional MIS weight. Overflowing
// sums (a near-mirror's densities) make it 0, never NaN.
float bidirectionalWeight(float others) { return std::isfinite(others) ? 1.0f / (1.0f + others) : 0.0f; }

// The density a camera vertex at `depth` is taken to sample a direction with, in the MIS weights of
// connections: the first vertex's own strategy (the guide), BSDF sampling past it, because that is
// what the light side, which cannot know a vertex's depth, evaluates for its vertices.
float cameraMisPdf(int depth, ContinuationSampler& continuation, const SurfaceHit& surface, const Bsdf& bsdf,
                   const glm::vec3& wo, const glm::vec3& wi, float bsdfPdf) {
  return depth == 0 ? continuation.pdf(surface, bsdf, wo, wi, bsdfPdf) : bsdfPdf;
}

}  // namespace

void PathTracer::MisSums::arrive(float distance, float cosHit) {
  dVCM *= connectionMis(distance * distance) / connectionMis(cosHit);
  dVC /= connectionMis(cosHit);
}

void PathTracer::MisSums::advance(int depth, const SurfaceHit& surface, const Bsdf& bsdf, const glm::vec3& wo,
                                  const DirectionSample& dir) {
  // The sample's own pdf is the BSDF's wherever the strategy left its weight (an unguided vertex).
  const float pdf = depth == 0 || dir.weight.x >= 0.0f ? dir.pdf : bsdf.pdf(wo, dir.wi);
  const float cosOut = std::abs(glm::dot(surface.geometricNormal, dir.wi));
  dVC = connectionMis(cosOut / pdf) * (dVC * connectionMis(bsdf.pdf(dir.wi, wo)) + dVCM);
  dVCM = connectionMis(1.0f / pdf);
}

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

float BsdfContinuation::pdf(const SurfaceHit&, const Bsdf&, const glm::vec3&, const glm::vec3&, float bsdfPdf) {
  return bsdfPdf;
}

PathTracer::PathTracer(const RenderScene& scene, const PathTracerSettings& settings, const IrradianceGrid* irradiance,
                       const LightVertexCache* connections, const EmitterGuide* emitterGuide)
    : scene_(scene), settings_(settings) {
  if (emitterGuide && emitterGuide->active()) emitterGuide_ = emitterGuide;
  if (connections && scene.emitters().supportsConnections()) connections_ = connections;
  const bool windowRule = settings_.roulette == RouletteRule::Vpl || settings_.roulette == RouletteRule::Auto;
  if (windowRule && irradiance && !irradiance->empty()) irradiance_ = irradiance;
}

float PathTracer::predictedRadiance(const glm::vec3& position, const glm::vec3& normal, const glm::vec3& reflectance) const {
  return luminance(glm::min(reflectance, glm::vec3(1.0f)) * irradiance_->irradiance(position, normal)) * kInvPi;
}

// A path waiting to be traced: a split vertex's other branches, each with its own numbers.
struct PathTracer::Branch {
  Ray ray;
  glm::vec3 beta{1.0f};
  // previousPosition: where the ray that is traced left (a surface: the camera's is never needed)
  PathPoint at;
  PixelSampler sampler;
  MisSums mis, alt;  // connections' partial sums: the pass's join depth's and a counterfactual one's
};

float PathTracer::nextEventPdf(const glm::vec3& p, const SurfaceHit& hit) const {
  return emitterGuide_ ? emitterGuide_->pdf(p, hit) : scene_.emitters().pdfTriangle(p, hit);
}

float PathTracer::emitterHitWeight(const SurfaceHit& surface, const glm::vec3& wo, const PathPoint& path,
                                   const MisSums& sums) const {
  if (path.depth == 0) return 1.0f;
  const EmitterSet& emitters = scene_.emitters();
  if (!connections_) return powerHeuristic(path.previousPdf, nextEventPdf(path.previousPosition, surface));
  const glm::vec3 d = surface.position - path.previousPosition;
  const float cosHit = std::abs(glm::dot(surface.geometricNormal, wo));
  const float directPdfArea = nextEventPdf(path.previousPosition, surface) * cosHit / glm::dot(d, d);
  return bidirectionalWeight(connectionMis(directPdfArea) * sums.dVCM + connectionMis(emitters.pdfEmission(surface, wo)) * sums.dVC);
}

float PathTracer::nextEventWeight(const LightSample& ls, const SurfaceHit& surface, const Bsdf& bsdf, const glm::vec3& wo,
                                  const Bsdf::Evaluation& toLight, int depth, const MisSums& sums,
                                  ContinuationSampler& continuation) const {
  if (!connections_) return ls.delta ? 1.0f : powerHeuristic(ls.pdf, continuation.pdf(surface, bsdf, wo, ls.wi, toLight.pdf));
  // Densities of punctual lights in the solid angle of the point they sit at (Georgiev 2012).
  const float directPdf = ls.delta && std::isfinite(ls.distance) ? ls.pdf * ls.distance * ls.distance : ls.pdf;
  const float wLight = ls.delta ? 0.0f : connectionMis(cameraMisPdf(depth, continuation, surface, bsdf, wo, ls.wi, toLight.pdf) / directPdf);
  // The light path that starts at the sampled point and reaches here, then shifts along the camera side.
  const float cameraSide = sums.dVCM + (sums.dVC > 0.0f ? sums.dVC * connectionMis(toLight.pdfReverse) : 0.0f);
  const float cosCamera = std::abs(glm::dot(surface.geometricNormal, ls.wi));
  const float wCamera = cameraSide > 0.0f ? connectionMis(ls.emissionPdf * cosCamera / (directPdf * ls.cosLight)) * cameraSide : 0.0f;
  return bidirectionalWeight(wLight + wCamera);
}

glm::vec3 PathTracer::unoccludedJoin(const SurfaceHit& surface, const Bsdf& bsdf, const glm::vec3& wo, int depth,
                                     const MisSums& mis, const MisSums& alt, ContinuationSampler& continuation,
                                     const LightVertex& y, float scale, Ray& shadow, int altLimit, glm::vec3& altJoined) const {
  if (depth + 1 + y.length > settings_.maxDepth) return glm::vec3(0.0f);
  const glm::vec3 d = y.position - surface.position;
  const float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.0f)) return glm::vec3(0.0f);
  const float dist = std::sqrt(dist2);
  const glm::vec3 w = d / dist;
  const float cosCamera = glm::dot(w, surface.geometricNormal), cosLight = -glm::dot(w, y.normal);
  if (!(cosCamera > 0.0f && cosLight > 0.0f)) return glm::vec3(0.0f);
  const Bsdf::Evaluation camera = bsdf.evalPdf(wo, w);
  if (isBlack(camera.f)) return glm::vec3(0.0f);
  const Bsdf::Evaluation light = y.bsdf.evalPdf(-w, y.wIn);
  if (isBlack(light.f)) return glm::vec3(0.0f);
  // Each side's density of making the other's end vertex, in area measure at that vertex, times the
  // ways of shifting the join further along that side (the partial sums).
  // The camera's density is cameraMisPdf's, with the BSDF's taken from the evaluation above. At the
  // first vertex the camera side has no other strategy (no light tracing to the camera): cameraSide
  // is 0 and its densities are not needed.
  const float cameraPdf = depth == 0 ? continuation.pdf(surface, bsdf, wo, w, camera.pdf) : camera.pdf;
  // The reverse densities came with the evaluations (a counterfactual's weight uses them too).
  const float reverseCamera = connectionMis(camera.pdfReverse);
  const float reverseLight = connectionMis(light.pdfReverse * cosCamera / dist2);
  const auto weightFor = [&](const MisSums& sums, int limit) {
    const float wLight = connectionMis(cameraPdf * cosLight / dist2) * LightVertexCache::lightSideSum(y, depth, light.pdf, limit);
    const float cameraSide = sums.dVCM + (sums.dVC > 0.0f ? sums.dVC * reverseCamera : 0.0f);
    const float wCamera = cameraSide > 0.0f ? reverseLight * cameraSide : 0.0f;
    // Over this join's own count (the other joins' counts are in the partial sums).
    return bidirectionalWeight((wLight + wCamera) / connections_->misFactor(y));
  };
  const float weight = weightFor(mis, connections_->joinDepth());
  if (!(weight > 0.0f)) return glm::vec3(0.0f);
  shadow = spawnShadowRay(surface, w, dist);
  if (altLimit != kNoCounterfactual && LightVertexCache::joinsAt(depth, altLimit))
    altJoined = camera.f * light.f * y.alpha * (cosLight / dist2 * scale * weightFor(alt, altLimit));
  return camera.f * light.f * y.alpha * (cosLight / dist2 * scale * weight);
}

glm::vec3 PathTracer::radiance(const Ray& cameraRay, PixelSampler& sampler, ContinuationSampler& continuation,
                               PathStats& stats, uint64_t pixel, JoinDepthCounterfactual* counterfactual) const {
  const EmitterSet& emitters = scene_.emitters();
  continuation.beginPath(pixel);
  glm::vec3 L(0.0f);
  // The counterfactual join depth's estimate, weighed alongside when this pass joins at every vertex.
  const bool alt = counterfactual && connections_ && connections_->joinDepth() < 0;
  const int altLimit = alt ? counterfactual->depth : kNoCounterfactual;
  glm::vec3 altL(0.0f);
  // The branches still to trace (kept per thread: most samples never split); `path` is being traced.
  static thread_local std::vector<Branch> pending;
  pending.clear();
  int branchesLeft = settings_.window.maxBranches - 1;
  uint32_t nextBranchId = 1;
  float pixelEstimate = 0.0f;  // the weight window's reference, set at the camera ray's hit
  glm::vec3 firstContinuationStart(0.0f);  // L before the first vertex's continuation

  Branch path{cameraRay, glm::vec3(1.0f), {}, sampler, {}, {}};
  for (;;) {
    Ray& ray = path.ray;
    glm::vec3& beta = path.beta;
    const int depth = path.at.depth;
    bool ended = true;
    do {
      VertexSamples u(path.sampler, depth);
      u.drawAhead();
      const RayHit hit = scene_.accel().intersect(ray);
      ++stats.rays;

      // Escaped: the sky, weighted against next-event estimation of the sky.
      if (!hit.valid()) {
        if (emitters.hasSky()) {
          float w = 1.0f;
          if (depth > 0) {
            const float skyPdf = emitterGuide_ ? emitterGuide_->pdfSky(path.at.previousPosition, ray.direction)
                                               : emitters.pdfSky(ray.direction);
            w = powerHeuristic(path.at.previousPdf, skyPdf);
          }
          L += beta * emitters.sky() * w;
        }
        break;
      }
      const SurfaceHit surface = scene_.surface(ray, hit);
      const glm::vec3 wo = -ray.direction;
      continuation.beginVertex(depth);
      if (connections_) {
        const float cosHit = std::abs(glm::dot(surface.geometricNormal, wo));
        if (!(cosHit > 0.0f)) break;
        path.mis.arrive(hit.t, cosHit);
        if (alt) path.alt.arrive(hit.t, cosHit);
      }

      // Emitter hit, weighted against next-event estimation of the same triangle (and, with
      // connections, against every join that makes the same path).
      const glm::vec3 le = emitters.emitted(surface, wo);
      if (!isBlack(le)) {
        L += beta * le * emitterHitWeight(surface, wo, path.at, path.mis);
        if (alt) altL += beta * le * emitterHitWeight(surface, wo, path.at, path.alt);
      }
      // From here on dVCM stands for a join with its light end at this vertex (for the emitter hit
      // above, next-event estimation's sample of it), which counts as the cache's factor of joins.
      // (A join from the vertex before this one, at depth - 1, which a join depth limit may forbid.)
      if (connections_) {
        const float factor = connections_->misFactor(surface.position);
        path.mis.dVCM *= connections_->joinsAt(depth - 1) ? factor : 0.0f;
        if (alt) path.alt.dVCM *= LightVertexCache::joinsAt(depth - 1, altLimit) ? factor : 0.0f;
      }
      if (depth + 1 > settings_.maxDepth) break;

      const Bsdf bsdf = scene_.bsdf(surface, wo);
      // The light vertices to join, picked now: next-event estimation's shadow ray hides their fetch.
      // n joins take one number u each, (j + u) / n: systematic, so they spread over the choice.
      std::array<const LightVertex*, LightVertexCache::kMaxJoinsPerVertex> joinTo;
      std::array<float, LightVertexCache::kMaxJoinsPerVertex> joinScale;
      int joins = 0;
      if (connections_ && depth + 2 <= settings_.maxDepth && !connections_->empty() && connections_->joinsAt(depth)) {
        joins = connections_->joinsPerVertex();
        const float uJoin = u.connectionChoice();
        for (int j = 0; j < joins; ++j) {
          joinTo[size_t(j)] = &connections_->pick((float(j) + uJoin) / float(joins), joinScale[size_t(j)]);
          for (size_t line = 0; line < sizeof(LightVertex); line += 64)
            __builtin_prefetch(reinterpret_cast<const char*>(joinTo[size_t(j)]) + line);
        }
      }

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
      const auto lightChoice = [&] { return u.lightChoice(); };
      const auto ls = emitterGuide_ ? emitterGuide_->sample(surface.position, u.lightPoint(), lightChoice)
                                    : emitters.sampleStratified(surface.position, u.lightPoint(), lightChoice);
      if (ls) {
        const float cosReceiver = glm::dot(ls->wi, surface.geometricNormal);
        const Bsdf::Evaluation toLight = cosReceiver > 0.0f ? bsdf.evalPdf(wo, ls->wi) : Bsdf::Evaluation{};
        const glm::vec3& f = toLight.f;
        if (!isBlack(f)) {
          ++stats.rays;
          if (emitterGuide_) emitterGuide_->attempted(ls->guideSlot);
          if (!scene_.accel().occluded(spawnShadowRay(surface, ls->wi, ls->distance))) {
            if (emitterGuide_) emitterGuide_->arrived(ls->guideSlot, EmitterGuide::arrivalValue(ls->radiance, cosReceiver, ls->pdf));
            const float w = nextEventWeight(*ls, surface, bsdf, wo, toLight, depth, path.mis, continuation);
            L += beta * f * ls->radiance * (w / ls->pdf);
            // At the camera ray's hit both depths' camera sums are 0, so the weights are the same.
            if (alt) altL += beta * f * ls->radiance * ((depth == 0 ? w : nextEventWeight(*ls, surface, bsdf, wo, toLight, depth, path.alt, continuation)) / ls->pdf);
          }
        }
      }

      // Joins to light vertices (the VPLs' share of the paths through here).
      for (int j = 0; j < joins; ++j) {
        const LightVertex& y = *joinTo[size_t(j)];
        Ray shadow;
        glm::vec3 altJoined(0.0f);
        glm::vec3 joined = beta * unoccludedJoin(surface, bsdf, wo, depth, path.mis, path.alt, continuation, y,
                                                 joinScale[size_t(j)], shadow, altLimit, altJoined);
        if (isBlack(joined)) continue;
        // Shadow-ray roulette: a join worth little against what the sample holds already rarely pays its ray.
        if (const float share = connections_->shadowRoulette(); share > 0.0f) {
          const float c = luminance(joined), threshold = share * luminance(L);
          if (c < threshold) {
            const float survival = std::max(c / threshold, ConnectionSettings::kMinShadowSurvival);
            if (u.random().uniform() >= survival) continue;
            joined /= survival;
            altJoined /= survival;
          }
        }
        ++stats.rays;
        if (alt && !LightVertexCache::joinsAt(depth, altLimit)) ++stats.raysPastCounterfactual;
        if (scene_.accel().occluded(shadow)) continue;
        connections_->record(y, luminance(joined));
        L += joined;
        if (alt) altL += beta * altJoined;
      }

      if (depth == 0) firstContinuationStart = L;

      // The split's other branches first (each its own numbers), then this path's own continuation.
      const glm::vec3 branchBeta = beta / float(split);
      for (int b = 1; b < split; ++b) {
        Branch next{Ray{}, glm::vec3(0.0f), {depth + 1, surface.position, 0.0f}, path.sampler.branch(nextBranchId++), path.mis, path.alt};
        VertexSamples ub(next.sampler, depth);
        DirectionSample dir;
        glm::vec3 weight;
        if (!sampleContinuation(surface, bsdf, wo, ub, continuation, stats, dir, weight)) continue;
        next.beta = branchBeta * weight;
        if (!isFiniteNonNegative(next.beta)) continue;
        if (connections_) next.mis.advance(depth, surface, bsdf, wo, dir);
        if (alt) next.alt.advance(depth, surface, bsdf, wo, dir);
        next.ray = spawnRay(surface, dir.wi);
        next.at.previousPdf = dir.pdf;
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
      if (connections_) path.mis.advance(depth, surface, bsdf, wo, next);
      if (alt) path.alt.advance(depth, surface, bsdf, wo, next);
      path.at = {depth + 1, surface.position, next.pdf};
      ray = spawnRay(surface, next.wi);
      ended = false;
    } while (false);
    if (!ended) continue;
    if (pending.empty()) break;
    path = pending.back();
    pending.pop_back();
  }
  continuation.endPath(L - firstContinuationStart);
  if (counterfactual) counterfactual->L = alt ? altL : L;
  return L;
}

}  // namespace vpl
