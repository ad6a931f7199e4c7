// One progressive pass = one sample in every pixel, rendered in 16x16 tiles over the TBB pool.
// The pass number is the pixels' sample index: samples are deterministic in (seed, pixel, pass), so
// the image does not depend on thread count, and each pixel's passes 0, 1, 2, ... walk one
// stratified sequence (render/sampling/pixel_sampler.h). Callers never reuse a pass number for a film.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include "render/film/film.h"
#include "render/integrator/path_lanes.h"
#include "render/integrator/path_tracer.h"
#include "render/integrator/sampling_mode.h"
#include "render/scene/camera.h"

namespace vpl {

class GuideField;
struct GuideLearners;

struct PassStats {
  uint64_t rays = 0;
  uint64_t samples = 0;
  uint64_t discarded = 0;  // non-finite or negative samples dropped before the film
  uint64_t bsdfSamples = 0, guideSamples = 0;
  uint64_t proposals = 0, accepted = 0;
  uint64_t branches = 0;
  uint64_t raysPastCounterfactual = 0;  // of `rays`: those a counterfactual join depth would not trace
  PassStats& operator+=(const PassStats& o) {
    rays += o.rays; samples += o.samples; discarded += o.discarded;
    bsdfSamples += o.bsdfSamples; guideSamples += o.guideSamples;
    proposals += o.proposals; accepted += o.accepted; branches += o.branches;
    raysPastCounterfactual += o.raysPastCounterfactual;
    return *this;
  }
};

// Radiance along one camera ray of pixel `pixel` (row-major index); a shader that joins light vertices
// also fills `counterfactual`, when given, and others leave it alone.
using PixelShader = std::function<glm::vec3(const Ray& ray, uint64_t pixel, PixelSampler& sampler, PathStats& stats,
                                            JoinDepthCounterfactual* counterfactual)>;
// Makes the shader of one tile and pass. Each tile gets its own, so per-tile state (such as Markov
// chains) is deterministic and never shared between threads.
using PixelShaderFactory = std::function<PixelShader(uint32_t tileIndex, uint64_t pass)>;

// The path tracer as a pixel shader, with a continuation strategy per tile (nullptr: BSDF sampling).
using ContinuationFactory = std::function<std::unique_ptr<ContinuationSampler>(uint32_t tileIndex, uint64_t pass)>;
PixelShaderFactory pathTracerShader(const PathTracer& tracer, ContinuationFactory continuation = nullptr);
// The guided modes' continuations: one per tile and pass, each writing its tile's logs of the
// learners (a learned BSDF probability for mis, learned guides; either may be absent).
ContinuationFactory guidedContinuations(const GuideField& guide, SamplingMode mode, const GuideLearners& learners);

class TileRenderer;
// `brdf`'s renderer of `tracer`'s samples: through PathLanes where the lanes model the tracer
// (path_lanes.h), else radiance() pixel by pixel. Replaces both; `lanes` must live as long as `renderer`.
// Returns the paths traced at once (PathLanes::kLanes or 1).
int emplaceBsdfRenderer(std::optional<TileRenderer>& renderer, std::optional<PathLanes>& lanes, const Camera& camera,
                        uint64_t seed, const PathTracer& tracer, bool stratified);

class TileRenderer {
 public:
  static constexpr int kTileSize = 16;

  // `stratified` false: independent random numbers instead of the stratified sampler (PixelSampler).
  TileRenderer(const Camera& camera, uint64_t seed, PixelShaderFactory shader, bool stratified = true);
  // `brdf` samples eight at a time: each tile through `lanes` (which must outlive the renderer), but
  // a pass that weighs a counterfactual join depth through `shader` (the lanes weigh none).
  TileRenderer(const Camera& camera, uint64_t seed, const PathLanes& lanes, PixelShaderFactory shader);

  // Adds one sample per pixel to film. Stops early (between tiles) when *stop becomes true.
  // `counterfactual`: also adds to it what each sample would have been with joins only up to camera
  // depth `counterfactualDepth` (PathTracer::radiance), for `--join-depth auto`.
  PassStats renderPass(Film& film, uint64_t pass, const std::atomic<bool>* stop = nullptr, Film* counterfactual = nullptr,
                       int counterfactualDepth = 1) const;

  int tileCount() const { return tilesX_ * tilesY_; }
  static int tileCountFor(int width, int height) {
    return ((width + kTileSize - 1) / kTileSize) * ((height + kTileSize - 1) / kTileSize);
  }

 private:
  Camera camera_;
  uint64_t seed_;
  PixelShaderFactory shader_;
  const PathLanes* lanes_ = nullptr;  // set: tiles go through the lanes, not shader_ (but see above)
  bool stratified_;
  int tilesX_, tilesY_;
};

}  // namespace vpl
