#include "render/vpl/gather.h"

#include <tbb/parallel_for.h>

namespace vpl {

CameraGather gatherPrimaryHits(const RenderScene& scene, const Camera& camera) {
  const int w = camera.width(), h = camera.height();
  const size_t pixels = size_t(w) * size_t(h);
  std::vector<uint8_t> valid(pixels, 0);
  std::vector<SurfaceHit> hits(pixels);
  std::vector<glm::vec3> wos(pixels);
  tbb::parallel_for(size_t(0), pixels, [&](size_t p) {
    const Ray ray = camera.generateRay(glm::vec2(float(p % size_t(w)) + 0.5f, float(p / size_t(w)) + 0.5f));
    const RayHit hit = scene.accel().intersect(ray);
    if (!hit.valid()) return;
    hits[p] = scene.surface(ray, hit);
    wos[p] = -ray.direction;
    // Emitters are shown as they are; they receive no VPL light in the preview.
    valid[p] = scene.data().materials[hits[p].material].isEmissive() ? 0 : 1;
  });
  CameraGather g;
  g.rays = pixels;
  g.pixelGather.assign(pixels, -1);
  for (size_t p = 0; p < pixels; ++p) {
    if (!valid[p]) continue;
    g.pixelGather[p] = int32_t(g.points.size());
    g.points.push_back({hits[p].position, hits[p].shadingNormal});
    g.hits.push_back(hits[p]);
    g.wo.push_back(wos[p]);
  }
  return g;
}

}  // namespace vpl
