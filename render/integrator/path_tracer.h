// Unidirectional path tracer with next-event estimation. The continuation direction at each vertex
// comes from the BSDF (`brdf`) or, in the guided modes, from the VPL guide (see render/guide/).
//
// Parameters (PathTracerSettings):
//   maxDepth      int   32    path segments from the camera; 1 = direct light only
//   rrStartDepth  int   5     first depth at which Russian roulette may end a path
//   roulette      enum  Auto  survival probability: min(1, sqrt(max throughput)) or min(1, max throughput),
//                             or Vpl: a weight window on the VPLs' estimate, with splitting (weight_window.h);
//                             Auto: Sqrt, or Vpl when the first passes vary more than their mean
//   window        WeightWindowSettings  the Vpl rule's window, split and branch limits
#pragma once
#include <cstdint>
#include <string>
#include <glm/glm.hpp>
#include "render/integrator/weight_window.h"
#include "render/sampling/pixel_sampler.h"
#include "render/scene/render_scene.h"

namespace vpl {

// How Russian roulette turns a path's throughput into a survival probability. The square root
// (Cycles' rule) ends dim paths later, at more cost per sample. Square root from depth 5 had the
// lowest equal-time error of six rules on three scenes (bench/roulette.sh, README). Vpl rules from
// depth 1 by the VPLs' estimate of what a path is still worth, and splits the paths worth more.
// Auto is Sqrt until its caller decides that the window pays (render/session/window_switch.h) and
// hands the tracer the VPLs' estimate.
enum class RouletteRule { Throughput, Sqrt, Vpl, Auto };

struct PathTracerSettings {
  int maxDepth = 32;
  int rrStartDepth = 5;
  RouletteRule roulette = RouletteRule::Auto;
  WeightWindowSettings window;
  // Next-event estimation learns which part of which emitter each region sees (EmitterGuide); the
  // tracer's owner makes the guide, since it learns between passes.
  bool learnLights = true;
  // `brdf` samples eight at a time in vector lanes where the scene allows (path_lanes.h); false: one
  // at a time through radiance() everywhere.
  bool lanes = true;

  // Empty when valid, else a readable reason.
  std::string validate() const;
};

// Counters of one worker; summed by the caller.
struct PathStats {
  uint64_t rays = 0;          // intersection + shadow rays
  uint64_t bsdfSamples = 0;   // continuation directions drawn from the BSDF
  uint64_t guideSamples = 0;  // continuation directions drawn from the guide
  uint64_t proposals = 0, accepted = 0;  // Metropolis mutations
  uint64_t branches = 0;      // extra paths grown by splitting (the vpl roulette rule)
  uint64_t raysPastCounterfactual = 0;  // shadow rays of joins that a counterfactual depth forbids
};

// What a camera sample would have brought back had its joins stopped at camera depth `depth`, weighed
// on the same paths as the sample itself (which joins at every vertex): `--join-depth auto` compares
// both estimators on the same passes instead of spending passes on the one that loses. Joins only
// change the weights and add shadow rays, never the camera path, so this is exactly the estimate a
// pass at that depth would have made from the same numbers (the rays it would not have traced are
// counted in PathStats::raysPastCounterfactual).
struct JoinDepthCounterfactual {
  int depth = 1;
  glm::vec3 L{0.0f};  // set by PathTracer::radiance: the sample's own when it has no joins to weigh
};

// How a vertex picks its continuation direction. The BSDF strategy is the reference; guided
// strategies implement the same interface so the tracer's MIS and weights stay one code path.
struct DirectionSample {
  glm::vec3 wi{0.0f};
  float pdf = 0.0f;  // solid angle density of the strategy as a whole (the density MIS needs)
  // f cos / pdf when the strategy already has it (plain BSDF sampling), so the tracer need not
  // evaluate the BSDF again; negative: not known, the tracer evaluates it.
  glm::vec3 weight{-1.0f};
};

class ContinuationSampler {
 public:
  virtual ~ContinuationSampler() = default;
  // Called at the start of every camera path, with its pixel (row-major index).
  virtual void beginPath(uint64_t /*pixel*/) {}
  // Called at every vertex before anything is asked there; depth 0 is the camera ray's hit. A split
  // path revisits depths, so a sampler must not count vertices itself.
  virtual void beginVertex(int /*depth*/) {}
  // Called when the camera sample is complete (all its branches traced), with the radiance its
  // paths brought back after the first vertex's next-event estimation: the estimate of the first
  // continuation direction, F / q (throughput is 1 there).
  virtual void endPath(const glm::vec3& /*firstContinuation*/) {}
  // Picks a direction at this vertex from its numbers `u`; returns false when the path should end.
  virtual bool sample(const SurfaceHit& hit, const Bsdf& bsdf, const glm::vec3& wo, VertexSamples& u,
                      DirectionSample& out, PathStats& stats) = 0;
  // Density with which sample() would return wi at this vertex; bsdfPdf is bsdf.pdf(wo, wi), which
  // every caller has from its own evaluation of the BSDF (Bsdf::evalPdf).
  virtual float pdf(const SurfaceHit& hit, const Bsdf& bsdf, const glm::vec3& wo, const glm::vec3& wi, float bsdfPdf) = 0;
};

// Plain BSDF importance sampling (the `brdf` mode).
class BsdfContinuation final : public ContinuationSampler {
 public:
  bool sample(const SurfaceHit& hit, const Bsdf& bsdf, const glm::vec3& wo, VertexSamples& u, DirectionSample& out,
              PathStats& stats) override;
  float pdf(const SurfaceHit& hit, const Bsdf& bsdf, const glm::vec3& wo, const glm::vec3& wi, float bsdfPdf) override;
};

class EmitterGuide;
class IrradianceGrid;
class LightVertexCache;
struct LightVertex;

class PathTracer {
 public:
  // `irradiance`: the VPLs' estimate that the Vpl and Auto rules need; without it (or with no light
  // in it) they are Sqrt, with it both are the window. It must outlive the tracer.
  // `connections`: light vertices to join every camera vertex to, weighted by bidirectional MIS
  // (light_vertex_cache.h); its owner rebuilds it between passes. Null, or a scene whose lights
  // connections do not support (EmitterSet::supportsConnections): none.
  // `emitterGuide`: learned next-event estimation (render/guide/emitter_guide.h), if active; its owner
  // updates it between passes, and builds `connections` with the same one.
  PathTracer(const RenderScene& scene, const PathTracerSettings& settings, const IrradianceGrid* irradiance = nullptr,
             const LightVertexCache* connections = nullptr, const EmitterGuide* emitterGuide = nullptr);

  // Radiance arriving along the camera ray, every decision drawn from its dimension of `sampler`.
  // May be non-finite only through a bug; callers check.
  // `counterfactual`: also weigh the sample as joins up to its depth would (only when this pass joins
  // at every vertex; otherwise it gets the sample's own radiance).
  glm::vec3 radiance(const Ray& cameraRay, PixelSampler& sampler, ContinuationSampler& continuation, PathStats& stats,
                     uint64_t pixel = 0, JoinDepthCounterfactual* counterfactual = nullptr) const;
  // The same with independent random numbers from `rng` (benches that trace paths of their own).
  glm::vec3 radiance(const Ray& cameraRay, Rng& rng, ContinuationSampler& continuation, PathStats& stats,
                     uint64_t pixel = 0) const {
    PixelSampler independent(rng);
    return radiance(cameraRay, independent, continuation, stats, pixel);
  }

  const PathTracerSettings& settings() const { return settings_; }
  const RenderScene& scene() const { return scene_; }
  // What radiance() uses beside the BSDF and the emitters (null when not in use).
  const EmitterGuide* emitterGuide() const { return emitterGuide_; }
  bool usesWeightWindow() const { return irradiance_ != nullptr; }
  // With the weight window: the radiance a diffuse reflector of `reflectance` at normal incidence
  // sends back from `position` (normal `normal`), as the VPLs predict it (luminance).
  float predictedRadiance(const glm::vec3& position, const glm::vec3& normal, const glm::vec3& reflectance) const;
  bool joinsLightVertices() const { return connections_ != nullptr; }

 // The camera side's MIS partial sums of connections (Georgiev 2012).
  struct MisSums {
    float dVC = 0.0f, dVCM = 0.0f;  // 0 at the camera: no light tracing to it
    // The ray that left the last vertex arrives `distance` away, at cosine `cosHit` with the surface.
    void arrive(float distance, float cosHit);
    // After a vertex samples `dir` (eq. 34-35); `depth` is the vertex's.
    void advance(int depth, const SurfaceHit& surface, const Bsdf& bsdf, const glm::vec3& wo, const DirectionSample& dir);
  };
  // Where a path stands at a vertex, for the MIS weights below: the vertex's depth, and the vertex
  // before it with the density its continuation was sampled with.
  struct PathPoint {
    int depth = 0;
    glm::vec3 previousPosition{0.0f};
    float previousPdf = 0.0f;
  };
  // MIS weights of an emitter hit and of a next-event sample: against each other alone, or with
  // connections against every join that makes the same path. `sums`: the path's own, or those of a
  // counterfactual join depth. `toLight`: bsdf.evalPdf(wo, ls.wi).
  float emitterHitWeight(const SurfaceHit& surface, const glm::vec3& wo, const PathPoint& path, const MisSums& sums) const;
  float nextEventWeight(const LightSample& ls, const SurfaceHit& surface, const Bsdf& bsdf, const glm::vec3& wo,
                        const Bsdf::Evaluation& toLight, int depth, const MisSums& sums,
                        ContinuationSampler& continuation) const;
  // The MIS-weighted contribution of joining camera vertex `surface` (at `depth`, with the sums `mis`)
  // to light vertex y, picked with weight `scale` (without the path's throughput), if `shadow`
  // arrives; 0 when y is too long or faces away. With a counterfactual depth (`altLimit`, the sums
  // `alt`), `altJoined` is the same join weighed for it (0 where it forbids the join, or where the
  // join's own weight is 0 and so no ray is traced).
  static constexpr int kNoCounterfactual = -100;  // a join depth limit that stands for none
  glm::vec3 unoccludedJoin(const SurfaceHit& surface, const Bsdf& bsdf, const glm::vec3& wo, int depth, const MisSums& mis,
                           const MisSums& alt, ContinuationSampler& continuation, const LightVertex& y, float scale,
                           Ray& shadow, int altLimit, glm::vec3& altJoined) const;
  // The light vertices joined to every camera vertex (null: none).
  const LightVertexCache* connections() const { return connections_; }

 private:
  struct Branch;
  // Radiance reflected at a vertex towards the path, as the VPLs predict it (luminance).
  float predictedRadiance(const SurfaceHit& surface, const Bsdf& bsdf) const {
    // A diffuse reflector of the BSDF's albedo at normal incidence: rough, but only ever a ratio's input.
    return predictedRadiance(surface.position, surface.geometricNormal, bsdf.params().diffuse + bsdf.params().f0);
  }
  // Next-event estimation's solid-angle density at p of an emitter hit's point.
  float nextEventPdf(const glm::vec3& p, const SurfaceHit& hit) const;

  const RenderScene& scene_;
  PathTracerSettings settings_;
  const IrradianceGrid* irradiance_ = nullptr;  // set only when the window is in use
  const LightVertexCache* connections_ = nullptr;  // set only when the scene's lights support them
  const EmitterGuide* emitterGuide_ = nullptr;     // set only when active
};

// Power heuristic with exponent 2 (Veach 1997, §9.2.4).
inline float powerHeuristic(float pdfA, float pdfB) {
  const float a = pdfA * pdfA, b = pdfB * pdfB;
  return a + b > 0.0f ? a / (a + b) : 0.0f;
}

}  // namespace vpl
