#include "render/session/tile_renderer.h"

#include <tbb/combinable.h>
#include <tbb/parallel_for.h>
#include "render/core/color.h"
#include "render/integrator/guided_continuation.h"

namespace vpl {

PixelShaderFactory pathTracerShader(const PathTracer& tracer, ContinuationFactory continuation) {
  if (!continuation) continuation = [](uint32_t, uint64_t) { return std::make_unique<BsdfContinuation>(); };
  return [&tracer, continuation](uint32_t tile, uint64_t pass) -> PixelShader {
    std::shared_ptr<ContinuationSampler> strategy = continuation(tile, pass);
    return [&tracer, strategy](const Ray& ray, uint64_t pixel, PixelSampler& sampler, PathStats& stats,
                               JoinDepthCounterfactual* counterfactual) {
      return tracer.radiance(ray, sampler, *strategy, stats, pixel, counterfactual);
    };
  };
}

ContinuationFactory guidedContinuations(const GuideField& guide, SamplingMode mode, const GuideLearners& learners) {
  return [&guide, mode, learners](uint32_t tile, uint64_t) {
    return std::make_unique<GuidedContinuation>(guide, mode, learners, tile);
  };
}

TileRenderer::TileRenderer(const Camera& camera, uint64_t seed, PixelShaderFactory shader, bool stratified)
    : camera_(camera), seed_(seed), shader_(std::move(shader)), stratified_(stratified),
      tilesX_((camera.width() + kTileSize - 1) / kTileSize), tilesY_((camera.height() + kTileSize - 1) / kTileSize) {}

int emplaceBsdfRenderer(std::optional<TileRenderer>& renderer, std::optional<PathLanes>& lanes, const Camera& camera,
                        uint64_t seed, const PathTracer& tracer, bool stratified) {
  renderer.reset();  // it may read the lanes
  lanes.reset();
  if (stratified && PathLanes::unsupported(tracer).empty()) {
    renderer.emplace(camera, seed, lanes.emplace(tracer), pathTracerShader(tracer));
    return PathLanes::kLanes;
  }
  renderer.emplace(camera, seed, pathTracerShader(tracer), stratified);
  return 1;
}

TileRenderer::TileRenderer(const Camera& camera, uint64_t seed, const PathLanes& lanes, PixelShaderFactory shader)
    : TileRenderer(camera, seed, std::move(shader), true) {
  lanes_ = &lanes;
}

PassStats TileRenderer::renderPass(Film& film, uint64_t pass, const std::atomic<bool>* stop, Film* counterfactual,
                                   int counterfactualDepth) const {
  tbb::combinable<PassStats> perThread;
  const int width = camera_.width(), height = camera_.height();
  tbb::parallel_for(0, tileCount(), [&](int tile) {
    if (stop && stop->load(std::memory_order_relaxed)) return;
    PassStats& stats = perThread.local();
    PathStats path;
    const int x0 = (tile % tilesX_) * kTileSize, y0 = (tile / tilesX_) * kTileSize;
    const int x1 = std::min(x0 + kTileSize, width), y1 = std::min(y0 + kTileSize, height);
    if (lanes_ && !counterfactual) {
      lanes_->renderTile(camera_, seed_, pass, x0, y0, x1, y1, film, path, stats.discarded);
      stats.samples += uint64_t(x1 - x0) * uint64_t(y1 - y0);
    } else {
      const PixelShader shade = shader_(uint32_t(tile), pass);
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          const uint64_t pixel = uint64_t(y) * uint64_t(width) + uint64_t(x);
          PixelSampler sampler(seed_, pixel, pass, stratified_);
          const Ray ray = camera_.generateRay(glm::vec2(float(x), float(y)) + sampler.cameraJitter());
          JoinDepthCounterfactual alternative{counterfactualDepth};
          // Set to the sample's own by any shader that does not weigh one.
          alternative.L = glm::vec3(-1.0f);
          const glm::vec3 L = shade(ray, pixel, sampler, path, counterfactual ? &alternative : nullptr);
          ++stats.samples;
          if (!isFiniteNonNegative(L)) {
            ++stats.discarded;
            continue;
          }
          film.addSample(x, y, L);
          if (counterfactual) counterfactual->addSample(x, y, isFiniteNonNegative(alternative.L) ? alternative.L : L);
        }
    }
    stats.rays += path.rays;
    stats.bsdfSamples += path.bsdfSamples;
    stats.guideSamples += path.guideSamples;
    stats.proposals += path.proposals;
    stats.accepted += path.accepted;
    stats.branches += path.branches;
    stats.raysPastCounterfactual += path.raysPastCounterfactual;
  });
  PassStats total;
  perThread.combine_each([&](const PassStats& s) { total += s; });
  return total;
}

}  // namespace vpl
