#include "render/session/ray_benchmark.h"

#include <atomic>
#include <chrono>
#include <vector>
#include <tbb/parallel_for.h>
#include "render/sampling/distribution_1d.h"
#include "render/sampling/rng.h"
#include "render/sampling/warps.h"
#include "render/scene/gltf_loader.h"
#include "render/scene/render_scene.h"

namespace vpl {

RayBenchmark measureRawRayRate(const std::string& scenePath, double seconds, uint64_t seed) {
  const RenderScene scene(loadGltf(scenePath));
  const SceneData& data = scene.data();

  // Area-weighted triangle choice over the whole scene.
  std::vector<std::pair<uint32_t, uint32_t>> triangles;
  std::vector<float> areas;
  for (uint32_t m = 0; m < data.meshes.size(); ++m) {
    const MeshData& mesh = data.meshes[m];
    for (uint32_t t = 0; 3 * t < mesh.indices.size(); ++t) {
      const glm::vec3 p0 = mesh.positions[mesh.indices[3 * t]], p1 = mesh.positions[mesh.indices[3 * t + 1]],
                      p2 = mesh.positions[mesh.indices[3 * t + 2]];
      triangles.emplace_back(m, t);
      areas.push_back(0.5f * glm::length(glm::cross(p1 - p0, p2 - p0)));
    }
  }
  const Distribution1D pick(areas);
  if (pick.empty()) return {};

  constexpr size_t kRayCount = 1 << 20;
  std::vector<Ray> rays(kRayCount);
  tbb::parallel_for(size_t(0), kRayCount, [&](size_t i) {
    Rng rng(seed, i);
    const auto [m, t] = triangles[pick.sample(rng.uniform())];
    const MeshData& mesh = data.meshes[m];
    const glm::vec3 p0 = mesh.positions[mesh.indices[3 * t]], p1 = mesh.positions[mesh.indices[3 * t + 1]],
                    p2 = mesh.positions[mesh.indices[3 * t + 2]];
    const glm::vec2 b = sampleUniformTriangle(rng.uniform2());
    const glm::vec3 n = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    const glm::vec3 d = sampleUniformSphere(rng.uniform2());
    const glm::vec3 magnitude = glm::max(glm::abs(p0), glm::max(glm::abs(p1), glm::abs(p2)));
    rays[i].origin = offsetRayOrigin(p0 * (1 - b.x - b.y) + p1 * b.x + p2 * b.y, glm::dot(d, n) >= 0 ? n : -n,
                                     std::max(magnitude.x, std::max(magnitude.y, magnitude.z)));
    rays[i].direction = d;
  });

  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  std::atomic<uint64_t> traced{0}, hits{0};
  double elapsed = 0.0;
  do {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, kRayCount, 4096), [&](const tbb::blocked_range<size_t>& r) {
      uint64_t h = 0;
      for (size_t i = r.begin(); i < r.end(); ++i) h += scene.accel().intersect(rays[i]).valid();
      hits += h;
      traced += r.size();
    });
    elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  } while (elapsed < seconds);
  RayBenchmark result;
  result.rays = traced.load();
  result.seconds = elapsed;
  result.raysPerSecond = double(result.rays) / elapsed;
  return result;
}

}  // namespace vpl
