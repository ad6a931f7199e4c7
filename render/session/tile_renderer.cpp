#include "render/session/tile_renderer.h"

#include <tbb/combinable.h>
#include <tbb/parallel_for.h>
#include "render/core/color.h"

namespace vpl {

TileRenderer::TileRenderer(const RenderScene& scene, const Camera& camera, const PathTracer& tracer, uint64_t seed,
                           ContinuationFactory continuation)
    : scene_(scene), camera_(camera), tracer_(tracer), seed_(seed), continuation_(std::move(continuation)),
      tilesX_((camera.width() + kTileSize - 1) / kTileSize), tilesY_((camera.height() + kTileSize - 1) / kTileSize) {
  if (!continuation_)
    continuation_ = [](uint32_t, uint64_t) { return std::make_unique<BsdfContinuation>(); };
}

PassStats TileRenderer::renderPass(Film& film, uint64_t pass, const std::atomic<bool>* stop) const {
  tbb::combinable<PassStats> perThread;
  const int width = camera_.width(), height = camera_.height();
  tbb::parallel_for(0, tileCount(), [&](int tile) {
    if (stop && stop->load(std::memory_order_relaxed)) return;
    PassStats& stats = perThread.local();
    PathStats path;
    auto continuation = continuation_(uint32_t(tile), pass);
    const int x0 = (tile % tilesX_) * kTileSize, y0 = (tile / tilesX_) * kTileSize;
    const int x1 = std::min(x0 + kTileSize, width), y1 = std::min(y0 + kTileSize, height);
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        const uint64_t pixel = uint64_t(y) * uint64_t(width) + uint64_t(x);
        Rng rng = Rng::forSample(seed_, pixel, pass);
        const glm::vec2 jitter = rng.uniform2();
        const Ray ray = camera_.generateRay(glm::vec2(float(x), float(y)) + jitter);
        const glm::vec3 L = tracer_.radiance(ray, rng, *continuation, path);
        ++stats.samples;
        if (!isFiniteNonNegative(L)) {
          ++stats.discarded;
          continue;
        }
        film.addSample(x, y, L);
      }
    stats.rays += path.rays;
    stats.bsdfSamples += path.bsdfSamples;
    stats.guideSamples += path.guideSamples;
  });
  PassStats total;
  perThread.combine_each([&](const PassStats& s) { total += s; });
  return total;
}

}  // namespace vpl
