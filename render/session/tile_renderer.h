// One progressive pass = one sample in every pixel, rendered in 16x16 tiles over the TBB pool.
// Samples are deterministic in (seed, pixel, pass): the image does not depend on thread count.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include "render/film/film.h"
#include "render/integrator/path_tracer.h"
#include "render/scene/camera.h"

namespace vpl {

struct PassStats {
  uint64_t rays = 0;
  uint64_t samples = 0;
  uint64_t discarded = 0;  // non-finite or negative samples dropped before the film
  uint64_t bsdfSamples = 0, guideSamples = 0;
  PassStats& operator+=(const PassStats& o) {
    rays += o.rays; samples += o.samples; discarded += o.discarded;
    bsdfSamples += o.bsdfSamples; guideSamples += o.guideSamples;
    return *this;
  }
};

// Makes the continuation strategy of one tile (each tile gets its own, so per-tile state such as
// Markov chains is deterministic and never shared between threads).
using ContinuationFactory = std::function<std::unique_ptr<ContinuationSampler>(uint32_t tileIndex, uint64_t pass)>;

class TileRenderer {
 public:
  static constexpr int kTileSize = 16;

  TileRenderer(const RenderScene& scene, const Camera& camera, const PathTracer& tracer, uint64_t seed,
               ContinuationFactory continuation);

  // Adds one sample per pixel to film. Stops early (between tiles) when *stop becomes true.
  PassStats renderPass(Film& film, uint64_t pass, const std::atomic<bool>* stop = nullptr) const;

  int tileCount() const { return tilesX_ * tilesY_; }

 private:
  const RenderScene& scene_;
  Camera camera_;
  const PathTracer& tracer_;
  uint64_t seed_;
  ContinuationFactory continuation_;
  int tilesX_, tilesY_;
};

}  // namespace vpl
