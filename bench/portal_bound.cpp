// How much could any directional guide gain on a scene lit through an opening? Every vertex that
// faces a given rectangle (a doorway, a window) samples a uniform point on it with probability 1/2
// and its BSDF otherwise (one-sample MIS, both exact pdfs), so it finds the opening as often as a
// guide that knew it exactly would; `--rect` off gives plain BSDF sampling on the same loop. Prints
// relMSE against a reference, the bias of the mean, the render time and relMSE x time (lower is better).
// Usage:
//   portal_bound SCENE REF.exr SPP [--rect CX CY CZ UX UY UZ VX VY VZ] [--rr-start N]
// The rectangle is centre C with half-edges U and V, seen from the side of U x V. two_rooms' doorway,
// seen from the camera's room: --rect 0 1.05 0 0 1.05 0 0 0 0.5
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <tbb/parallel_for.h>
#include "render/core/error.h"
#include "render/film/image_io.h"
#include "render/film/image_metrics.h"
#include "render/integrator/path_tracer.h"
#include "render/scene/camera.h"
#include "render/scene/gltf_loader.h"

using namespace vpl;

namespace {

struct Rectangle {
  glm::vec3 centre{0.0f}, u{0.0f}, v{0.0f};  // half-edges
  glm::vec3 normal() const { return glm::normalize(glm::cross(u, v)); }
  float area() const { return 4.0f * glm::length(glm::cross(u, v)); }
};

class RectangleContinuation final : public ContinuationSampler {
 public:
  explicit RectangleContinuation(const Rectangle& r) : rect_(r), normal_(r.normal()) {}

  bool sample(const SurfaceHit& hit, const Bsdf& bsdf, const glm::vec3& wo, VertexSamples& samples, DirectionSample& out,
              PathStats& stats) override {
    if (!faces(hit) || samples.strategy() < 0.5f) {
      const auto s = bsdf.sample(wo, samples.bsdfDirection());
      if (!s) return false;
      out.wi = s->wi;
    } else {
      const glm::vec2 u = samples.guidePoint() * 2.0f - 1.0f;
      out.wi = glm::normalize(rect_.centre + u.x * rect_.u + u.y * rect_.v - hit.position);
    }
    ++stats.bsdfSamples;
    out.pdf = pdf(hit, bsdf, wo, out.wi, bsdf.pdf(wo, out.wi));
    return out.pdf > 0.0f;
  }

  float pdf(const SurfaceHit& hit, const Bsdf&, const glm::vec3&, const glm::vec3& wi, float bsdfPdf) override {
    if (!faces(hit)) return bsdfPdf;
    return 0.5f * bsdfPdf + 0.5f * rectanglePdf(hit.position, wi);
  }

 private:
  Rectangle rect_;
  glm::vec3 normal_;

  // Sampled from the side its normal points to (U x V), by vertices whose hemisphere holds it well.
  bool faces(const SurfaceHit& hit) const {
    const glm::vec3 d = rect_.centre - hit.position;
    const float len = glm::length(d);
    return glm::dot(d, normal_) < -1e-3f && glm::dot(d, hit.shadingNormal) > 0.3f * len;
  }
  // Solid-angle density of a uniform point on the rectangle seen from p along wi.
  float rectanglePdf(const glm::vec3& p, const glm::vec3& wi) const {
    const float cosN = glm::dot(wi, normal_);
    if (std::fabs(cosN) < 1e-6f) return 0.0f;
    const float t = glm::dot(rect_.centre - p, normal_) / cosN;
    if (!(t > 0.0f)) return 0.0f;
    const glm::vec3 q = p + t * wi - rect_.centre;
    const float su = glm::dot(q, rect_.u) / glm::dot(rect_.u, rect_.u), sv = glm::dot(q, rect_.v) / glm::dot(rect_.v, rect_.v);
    if (std::fabs(su) > 1.0f || std::fabs(sv) > 1.0f) return 0.0f;
    return t * t / (std::fabs(cosN) * rect_.area());
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: portal_bound SCENE REF.exr SPP [--rect CX CY CZ UX UY UZ VX VY VZ] [--rr-start N]\n");
    return 2;
  }
  try {
    const RenderScene scene(loadGltf(argv[1]));
    const Image reference = readExr(argv[2]);
    const int spp = std::atoi(argv[3]);
    PathTracerSettings settings;
    bool useRect = false;
    Rectangle rect;
    for (int i = 4; i < argc; ++i) {
      if (!std::strcmp(argv[i], "--rect") && i + 9 < argc) {
        float x[9];
        for (float& xi : x) xi = float(std::atof(argv[++i]));
        rect = {{x[0], x[1], x[2]}, {x[3], x[4], x[5]}, {x[6], x[7], x[8]}};
        useRect = true;
      } else if (!std::strcmp(argv[i], "--rr-start") && i + 1 < argc) {
        settings.rrStartDepth = std::atoi(argv[++i]);
      } else {
        std::fprintf(stderr, "portal_bound: unknown or incomplete option %s\n", argv[i]);
        return 2;
      }
    }
    if (spp < 1 || !settings.validate().empty() || (useRect && !(rect.area() > 0.0f))) {
      std::fprintf(stderr, "portal_bound: bad samples, rectangle or Russian roulette depth\n");
      return 2;
    }
    const Camera camera(defaultCamera(scene.data()), reference.width, reference.height);
    const PathTracer tracer(scene, settings);
    Image image(reference.width, reference.height);
    const auto start = std::chrono::steady_clock::now();
    tbb::parallel_for(0, reference.height, [&](int y) {
      RectangleContinuation guided(rect);
      BsdfContinuation plain;
      ContinuationSampler& continuation = useRect ? static_cast<ContinuationSampler&>(guided) : plain;
      PathStats stats;
      for (int x = 0; x < reference.width; ++x) {
        Rng rng(4242, uint64_t(y) * uint64_t(reference.width) + uint64_t(x));
        glm::vec3 sum(0.0f);
        for (int s = 0; s < spp; ++s) sum += tracer.radiance(camera.generateRay(glm::vec2(x, y) + rng.uniform2()), rng, continuation, stats);
        image.at(x, y) = sum / float(spp);
      }
    });
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double error = relMse(image, reference);
    std::printf("%s rr-start %d spp %d: relMSE %.5f bias %+.4f time %.2f s relMSE x time %.4f\n",
                useRect ? "rectangle+bsdf" : "bsdf", settings.rrStartDepth, spp, error, relativeBias(image, reference),
                seconds, error * seconds);
  } catch (const InputError& e) {
    std::fprintf(stderr, "portal_bound: %s\n", e.what());
    return 2;
  }
  return 0;
}
