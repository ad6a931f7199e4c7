#include "render/vpl/gather.h"

#include <tbb/parallel_for.h>

namespace vpl {

namespace {

Ray pixelCentreRay(const Camera& camera, size_t pixel) {
  const size_t w = size_t(camera.width());
  return camera.generateRay(glm::vec2(float(pixel % w) + 0.5f, float(pixel / w) + 0.5f));
}

}  // namespace

CameraGather gatherPrimaryHits(const RenderScene& scene, const Camera& camera) {
  const size_t pixels = size_t(camera.width()) * size_t(camera.height());
  // Two passes, so that the gather points' arrays are allocated once, at their final size: memory, not
  // tracing, was the cost (at 800x600, 34 ms of tracing in a 0.46-0.56 s stage, the rest filling a
  // per-pixel SurfaceHit array and growing the compacted ones from it).
  // 1. Trace, keeping only the small hit record; emitters are shown as they are and receive no VPL light.
  std::vector<RayHit> primary(pixels);
  tbb::parallel_for(size_t(0), pixels, [&](size_t p) {
    const RayHit hit = scene.accel().intersect(pixelCentreRay(camera, p));
    if (hit.valid() && !scene.data().materials[scene.data().meshes[hit.mesh].material].isEmissive()) primary[p] = hit;
  });
  CameraGather g;
  g.rays = pixels;
  g.pixelGather.resize(pixels);
  int32_t count = 0;
  for (size_t p = 0; p < pixels; ++p) g.pixelGather[p] = primary[p].valid() ? count++ : -1;
  // 2. The surface at each hit, straight into its gather point's slot.
  g.points.resize(size_t(count));
  g.hits.resize(size_t(count));
  g.wo.resize(size_t(count));
  tbb::parallel_for(size_t(0), pixels, [&](size_t p) {
    const int32_t i = g.pixelGather[p];
    if (i < 0) return;
    const Ray ray = pixelCentreRay(camera, p);
    const SurfaceHit& hit = g.hits[size_t(i)] = scene.surface(ray, primary[p]);
    g.points[size_t(i)] = {hit.position, hit.shadingNormal};
    g.wo[size_t(i)] = -ray.direction;
  });
  return g;
}

}  // namespace vpl
