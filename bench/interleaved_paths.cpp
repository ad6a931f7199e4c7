// Would tracing several camera paths in lockstep make a brdf sample cheaper? A path vertex is a long
// chain of dependent arithmetic (hashes, square roots, divisions, table reads) between two Embree
// calls; K independent paths advanced stage by stage put K such chains side by side, where an
// out-of-order core can overlap them. This bench runs the same estimator as PathTracer::radiance in
// --mode brdf (next-event estimation with MIS, square-root roulette from depth rr-start, no
// connections, no weight window) with K = 1, 2, 4 lanes, single-threaded, against radiance() itself,
// and prints the time per sample and the image mean of each (equal: the same estimator on the same
// numbers, so every lane count makes radiance()'s image).
// Usage: interleaved_paths SCENE [WIDTH HEIGHT PASSES ROUNDS]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <vector>
#include "render/core/color.h"
#include "render/integrator/path_tracer.h"
#include "render/sampling/pixel_sampler.h"
#include "render/scene/camera.h"
#include "render/scene/gltf_loader.h"

using namespace vpl;

namespace {

// K paths of one batch of pixels, advanced one vertex at a time, each stage over all lanes.
template <int K>
void traceLanes(const RenderScene& scene, const PathTracerSettings& settings, PixelSampler* const* samplers, const Ray* cameraRays,
                glm::vec3* out) {
  const EmitterSet& emitters = scene.emitters();
  Ray ray[K];
  glm::vec3 beta[K], L[K], previousPosition[K];
  float previousPdf[K];
  bool alive[K];
  for (int k = 0; k < K; ++k) {
    ray[k] = cameraRays[k];
    beta[k] = glm::vec3(1.0f);
    L[k] = glm::vec3(0.0f);
    previousPdf[k] = 0.0f;
    alive[k] = true;
  }
  for (int depth = 0;; ++depth) {
    bool any = false;
    for (int k = 0; k < K; ++k) any = any || alive[k];
    if (!any) break;
    std::optional<VertexSamples> u[K];
    RayHit hit[K];
    for (int k = 0; k < K; ++k)
      if (alive[k]) {
        u[k].emplace(*samplers[k], depth);
        u[k]->drawAhead();
        hit[k] = scene.accel().intersect(ray[k]);
      }
    SurfaceHit surface[K];
    Bsdf bsdf[K];
    glm::vec3 wo[K];
    for (int k = 0; k < K; ++k) {
      if (!alive[k]) continue;
      if (!hit[k].valid()) {
        if (emitters.hasSky())
          L[k] += beta[k] * emitters.sky() * (depth == 0 ? 1.0f : powerHeuristic(previousPdf[k], emitters.pdfSky(ray[k].direction)));
        alive[k] = false;
        continue;
      }
      surface[k] = scene.surface(ray[k], hit[k]);
      wo[k] = -ray[k].direction;
      const glm::vec3 le = emitters.emitted(surface[k], wo[k]);
      if (!isBlack(le))
        L[k] += beta[k] * le *
                (depth == 0 ? 1.0f : powerHeuristic(previousPdf[k], emitters.pdfTriangle(previousPosition[k], surface[k])));
      if (depth + 1 > settings.maxDepth) {
        alive[k] = false;
        continue;
      }
      bsdf[k] = scene.bsdf(surface[k], wo[k]);
    }
    std::optional<LightSample> light[K];
    glm::vec3 f[K];
    Ray shadow[K];
    bool test[K];
    for (int k = 0; k < K; ++k) {
      test[k] = false;
      if (!alive[k]) continue;
      VertexSamples& uk = *u[k];
      light[k] = emitters.sampleStratified(surface[k].position, uk.lightPoint(), [&] { return uk.lightChoice(); });
      if (!light[k]) continue;
      f[k] = glm::dot(light[k]->wi, surface[k].geometricNormal) > 0.0f ? bsdf[k].eval(wo[k], light[k]->wi) : glm::vec3(0.0f);
      if (isBlack(f[k])) continue;
      shadow[k] = spawnShadowRay(surface[k], light[k]->wi, light[k]->distance);
      test[k] = true;
    }
    for (int k = 0; k < K; ++k)
      if (test[k] && !scene.accel().occluded(shadow[k])) {
        const LightSample& ls = *light[k];
        const float w = ls.delta ? 1.0f : powerHeuristic(ls.pdf, bsdf[k].pdf(wo[k], ls.wi));
        L[k] += beta[k] * f[k] * ls.radiance * (w / ls.pdf);
      }
    for (int k = 0; k < K; ++k) {
      if (!alive[k]) continue;
      alive[k] = false;
      const auto s = bsdf[k].sample(wo[k], u[k]->bsdfDirection());
      if (!s || !(s->pdf > 0.0f) || isBlack(s->weight) || !(glm::dot(s->wi, surface[k].geometricNormal) > 0.0f)) continue;
      beta[k] *= s->weight;
      if (!isFiniteNonNegative(beta[k])) continue;
      if (depth + 1 >= settings.rrStartDepth) {
        const float survive = std::min(1.0f, std::sqrt(maxComponent(beta[k])));
        if (u[k]->roulette() >= survive) continue;
        beta[k] /= survive;
      }
      previousPosition[k] = surface[k].position;
      previousPdf[k] = s->pdf;
      ray[k] = spawnRay(surface[k], s->wi);
      alive[k] = true;
    }
  }
  for (int k = 0; k < K; ++k) out[k] = L[k];
}

using Clock = std::chrono::steady_clock;

struct Result {
  double seconds = 0.0;
  double mean = 0.0;
};

// Every pixel of every pass, batches of K consecutive pixels (K = 0: PathTracer::radiance).
template <int K>
Result render(const RenderScene& scene, const Camera& camera, const PathTracer& tracer, const PathTracerSettings& settings,
              int passes) {
  const int width = camera.width(), height = camera.height();
  const int pixels = width * height;
  BsdfContinuation continuation;
  PathStats stats;
  double sum = 0.0;
  const auto start = Clock::now();
  constexpr int kBatch = K > 0 ? K : 1;
  for (int pass = 0; pass < passes; ++pass)
    for (int p0 = 0; p0 + kBatch <= pixels; p0 += kBatch) {
      std::optional<PixelSampler> samplers[kBatch];
      PixelSampler* lanes[kBatch];
      Ray rays[kBatch];
      for (int k = 0; k < kBatch; ++k) {
        const int p = p0 + k;
        samplers[k].emplace(1, uint64_t(p), uint64_t(pass));
        lanes[k] = &*samplers[k];
        rays[k] = camera.generateRay(glm::vec2(float(p % width), float(p / width)) + samplers[k]->cameraJitter());
      }
      glm::vec3 L[kBatch];
      if constexpr (K == 0) {
        L[0] = tracer.radiance(rays[0], *lanes[0], continuation, stats, uint64_t(p0));
      } else {
        traceLanes<K>(scene, settings, lanes, rays, L);
      }
      for (int k = 0; k < kBatch; ++k)
        if (isFiniteNonNegative(L[k])) sum += double(luminance(L[k]));
    }
  Result r;
  r.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  r.mean = sum / (double(pixels) * passes);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && argc != 6) {
    std::fprintf(stderr, "usage: interleaved_paths SCENE [WIDTH HEIGHT PASSES ROUNDS]\n");
    return 2;
  }
  try {
    const RenderScene scene(loadGltf(argv[1]));
    const int width = argc == 6 ? std::atoi(argv[2]) : 256, height = argc == 6 ? std::atoi(argv[3]) : 256;
    const int passes = argc == 6 ? std::atoi(argv[4]) : 4, rounds = argc == 6 ? std::atoi(argv[5]) : 5;
    if (width < 4 || height < 1 || passes < 1 || rounds < 1) {
      std::fprintf(stderr, "interleaved_paths: bad size, passes or rounds\n");
      return 2;
    }
    const Camera camera(defaultCamera(scene.data()), width, height);
    PathTracerSettings settings;
    settings.roulette = RouletteRule::Sqrt;
    const PathTracer tracer(scene, settings);
    const double samples = double(width) * height * passes;
    std::vector<double> t[4];
    double mean[4] = {};
    for (int round = 0; round < rounds; ++round) {
      const Result r0 = render<0>(scene, camera, tracer, settings, passes);
      const Result r1 = render<1>(scene, camera, tracer, settings, passes);
      const Result r2 = render<2>(scene, camera, tracer, settings, passes);
      const Result r4 = render<4>(scene, camera, tracer, settings, passes);
      const Result* all[4] = {&r0, &r1, &r2, &r4};
      for (int i = 0; i < 4; ++i) {
        t[i].push_back(all[i]->seconds);
        mean[i] = all[i]->mean;
      }
    }
    const char* names[4] = {"radiance()", "1 lane", "2 lanes", "4 lanes"};
    for (auto& v : t) std::sort(v.begin(), v.end());
    const double base = t[0][t[0].size() / 2];
    for (int i = 0; i < 4; ++i) {
      const double median = t[i][t[i].size() / 2];
      std::printf("%-11s %7.1f ns/sample (median of %d)  x%.3f of radiance()  mean %.6f\n", names[i], median / samples * 1e9,
                  rounds, median / base, mean[i]);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "interleaved_paths: %s\n", e.what());
    return 2;
  }
  return 0;
}
