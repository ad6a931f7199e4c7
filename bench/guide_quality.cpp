// How good is the VPL guide as a sampling density, before any cost is counted? At sampled cache
// points it estimates the indirect light that the continuation direction must find,
//   g(w) = f(wo, w) cos(w) L_ind(w),   L_ind = what the next vertex reflects (its emission excluded),
// on a stratified set of directions (L_ind by brdf path tracing), and prints for each strategy the
// variance of the one-sample estimator g/p relative to BSDF sampling: below 1 the strategy beats
// the BSDF at equal sample count. The "oracle" column is the best a tabulated guide could do: g
// itself, estimated with independent paths, on the same equal-area map and mixed with the BSDF as
// `mis` is (it bounds what a better target could gain at this vertex). Usage:
//   guide_quality SCENE [cache points=48] [directions=4096] [paths per direction=8] [width=320] [height=240]
// The oracle is learned at other directions of the same strata than those it is judged on, with its
// own paths (a table of cells cannot know g at the test direction); it needs about 4 directions per
// cell and well-converged g (4096 directions x 64 paths) or its own noise makes it look worse than it is.
// Environment overrides of the defaults: GQ_VPLS (count), GQ_CONE (degrees), GQ_DEFENSIVE, GQ_CLAMP, GQ_SPREAD;
// GQ_UNCLUSTERED=1 builds the guide from every VPL (no clustering); GQ_ORACLE_CONE (degrees) blurs the oracle.
// GQ_DUMP=C prints cache point C and each direction's share of the guide's second moment on stderr.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <vector>
#include <tbb/parallel_for.h>
#include "render/core/color.h"
#include "render/core/error.h"
#include "render/guide/guide_builder.h"
#include "render/scene/camera.h"
#include "render/scene/gltf_loader.h"
#include "render/sampling/warps.h"

using namespace vpl;

namespace {

struct Moments {
  double mean = 0.0, bsdf = 0.0, guide = 0.0, mis = 0.0;  // integral, then second moments E_p[(g/p)^2]
  double oracle = 0.0;  // an ideal tabulated guide: g itself (from independent paths) on the same map, mixed as mis
};

// The same target built from every VPL (no clustering), each with its own visibility test.
GuideDistribution unclustered(const RenderScene& scene, const VplField& vplField, const SurfaceHit& at, float cone, float defensive) {
  std::vector<GuideRepresentative> reps;
  for (const Vpl& light : vplField.vpls->vpls) {
    const auto arrival = vplArrival(light, at, vplField.minDistance);
    if (arrival && !scene.accel().occluded(spawnShadowRay(at, arrival->direction, arrival->distance)))
      reps.push_back({arrival->direction, arrival->weight, 0.0f});
  }
  return GuideDistribution(reps, cone, defensive);
}

// g(w) = f(wo, w) cos L_ind(w) by `paths` brdf paths: the light the next vertex reflects, its emission excluded.
double indirect(const RenderScene& scene, const PathTracer& tracer, const SurfaceHit& at, const Bsdf& bsdf, const glm::vec3& wo,
                const glm::vec3& w, int paths, Rng& rng, BsdfContinuation& continuation, PathStats& stats) {
  const glm::vec3 f = bsdf.eval(wo, w);
  if (isBlack(f) || glm::dot(w, at.shadingNormal) <= 0.0f) return 0.0;
  glm::vec3 l(0.0f);
  const Ray ray = spawnRay(at, w);
  for (int k = 0; k < paths; ++k) l += tracer.radiance(ray, rng, continuation, stats);
  const RayHit hit = scene.accel().intersect(ray);
  if (hit.valid()) l -= float(paths) * scene.emitters().emitted(scene.surface(ray, hit), -w);  // next-event estimation's share
  return std::max(0.0f, luminance(f * l)) / paths;
}

// Stratified uniform sphere directions: each carries g and all strategies' pdfs.
Moments measure(const RenderScene& scene, const PathTracer& tracer, const GuideField& field, const VplField& vplField,
                int c, const glm::vec3& wo, int directions, int paths, uint64_t seed) {
  CachePoint cp = field.point(c);
  SurfaceHit at;
  at.position = cp.position;
  at.shadingNormal = cp.normal;
  at.geometricNormal = cp.normal;
  at.coordinateScale = scene.coordinateScale();
  const Bsdf bsdf = scene.bsdf(at);
  if (std::getenv("GQ_UNCLUSTERED"))
    cp.distribution = unclustered(scene, vplField, at, field.settings().coneAngle, field.settings().defensive);
  const int side = int(std::sqrt(double(directions)));
  const float pBsdf = field.settings().bsdfProbability;
  Moments m;
  const bool dump = std::getenv("GQ_DUMP") && std::atoi(std::getenv("GQ_DUMP")) == c;
  Rng rng(seed, uint64_t(c));
  struct Sample { glm::vec3 wTest; double g; glm::vec3 wTrain; float gTrain; };  // judged at wTest, the oracle learns at wTrain
  std::vector<Sample> samples;
  BsdfContinuation continuation;
  PathStats stats;
  for (int i = 0; i < side * side; ++i) {
    const glm::vec2 u((float(i % side) + rng.uniform()) / side, (float(i / side) + rng.uniform()) / side);
    const glm::vec3 w = sampleUniformSphere(u);
    const glm::vec3 f = bsdf.eval(wo, w);
    if (isBlack(f) || glm::dot(w, cp.normal) <= 0.0f) continue;
    // The oracle learns g at another direction of the same stratum, with its own paths: it must not
    // read g at the very direction it is judged on, which a table of cells could not do either.
    const glm::vec3 wTrain =
        sampleUniformSphere({(float(i % side) + rng.uniform()) / side, (float(i / side) + rng.uniform()) / side});
    const double g = indirect(scene, tracer, at, bsdf, wo, w, paths, rng, continuation, stats);
    samples.push_back({w, g, wTrain, float(indirect(scene, tracer, at, bsdf, wo, wTrain, paths, rng, continuation, stats))});
    const double pu = uniformSpherePdf(), pb = bsdf.pdf(wo, w), pg = cp.distribution.pdf(w);
    const double pm = pBsdf * pb + (1.0 - pBsdf) * pg;
    const double n = double(side) * side;
    m.mean += g / pu / n;
    m.bsdf += (pb > 0 ? g * g / (pb * pu) : (g > 0 ? INFINITY : 0.0)) / n;
    m.guide += g * g / (pg * pu) / n;
    m.mis += g * g / (pm * pu) / n;
    if (dump && g > 0)
      std::fprintf(stderr, "w %6.3f %6.3f %6.3f cos %.3f g %.4g pg %.4g pb %.4g g2/pg %.4g\n", w.x, w.y, w.z,
                   glm::dot(w, cp.normal), g, pg, pb, g * g / (pg * pu) / n);
  }
  std::vector<GuideRepresentative> truth;
  for (const Sample& x : samples) truth.push_back({x.wTrain, x.gTrain, 0.0f});
  const float oracleCone = std::getenv("GQ_ORACLE_CONE") ? float(std::atof(std::getenv("GQ_ORACLE_CONE")) * kPi / 180.0) : 0.0f;
  const GuideDistribution oracle(truth, oracleCone, cp.distribution.defensive());
  for (const Sample& x : samples) {
    const double pm = pBsdf * bsdf.pdf(wo, x.wTest) + (1.0 - pBsdf) * oracle.pdf(x.wTest);
    m.oracle += x.g * x.g / (pm * uniformSpherePdf()) / (double(side) * side);
  }
  if (dump)
    std::fprintf(stderr, "cache %d at %.3f %.3f %.3f n %.3f %.3f %.3f radius %.3f\n", c, cp.position.x, cp.position.y,
                 cp.position.z, cp.normal.x, cp.normal.y, cp.normal.z, cp.radius);
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: guide_quality SCENE [cache points] [directions] [paths per direction] [width] [height]\n");
    return 2;
  }
  const int points = argc > 2 ? std::atoi(argv[2]) : 48, directions = argc > 3 ? std::atoi(argv[3]) : 4096;
  const int paths = argc > 4 ? std::atoi(argv[4]) : 8;
  const int width = argc > 5 ? std::atoi(argv[5]) : 320, height = argc > 6 ? std::atoi(argv[6]) : 240;
  try {
    const RenderScene scene(loadGltf(argv[1]));
    const Camera camera(defaultCamera(scene.data()), width, height);
    PreviewSettings preview;
    GuideSettings guideSettings;
    if (const char* v = std::getenv("GQ_VPLS")) preview.vpl.count = std::atoi(v);
    if (const char* v = std::getenv("GQ_CONE")) guideSettings.coneAngle = float(std::atof(v) * kPi / 180.0);
    if (const char* v = std::getenv("GQ_DEFENSIVE")) guideSettings.defensive = float(std::atof(v));
    if (const char* v = std::getenv("GQ_SPREAD")) guideSettings.spreadScale = float(std::atof(v));
    if (const char* v = std::getenv("GQ_CLAMP")) preview.clampFraction = float(std::atof(v));
    const VplField vplField = buildVplField(scene, camera, std::make_shared<VplSet>(traceVpls(scene, preview.vpl)), preview);
    const GuideField field = buildGuideField(scene, vplField, guideSettings);
    const PathTracer tracer(scene, PathTracerSettings{});
    std::vector<Moments> results(size_t(std::min<size_t>(points, field.size())));
    tbb::parallel_for(size_t(0), results.size(), [&](size_t i) {
      const int c = int(i * field.size() / results.size());
      const uint32_t g = vplField.tree.slices[size_t(c)].representative;
      results[i] = measure(scene, tracer, field, vplField, c, vplField.gather.wo[g], directions, paths, 7);
    });
    std::printf("%5s %10s %10s %10s %10s %10s %6s\n", "cache", "integral", "rel bsdf", "var guide", "var mis", "var oracle", "reps");
    std::vector<double> guideRatio, misRatio, oracleRatio, relBsdf;
    for (size_t i = 0; i < results.size(); ++i) {
      const Moments& m = results[i];
      const double vb = m.bsdf - m.mean * m.mean, vg = m.guide - m.mean * m.mean, vm = m.mis - m.mean * m.mean;
      if (!(vb > 0)) continue;
      guideRatio.push_back(vg / vb);
      misRatio.push_back(vm / vb);
      const double vo = m.oracle - m.mean * m.mean;
      oracleRatio.push_back(vo / vb);
      relBsdf.push_back(vb / (m.mean * m.mean));
      const int c = int(i * field.size() / results.size());
      std::printf("%5d %10.4g %10.3f %10.3f %10.3f %10.3f %6zu\n", c, m.mean, vb / (m.mean * m.mean), vg / vb, vm / vb, vo / vb,
                  field.point(c).distribution.size());
    }
    auto median = [](std::vector<double> v) { std::sort(v.begin(), v.end()); return v.empty() ? 0.0 : v[v.size() / 2]; };
    auto mean = [](const std::vector<double>& v) { double s = 0; for (double x : v) s += x; return v.empty() ? 0.0 : s / v.size(); };
    std::printf("variance relative to BSDF sampling: guide median %.3f mean %.3f, mis median %.3f mean %.3f, "
                "oracle mis median %.3f mean %.3f; BSDF sampling's relative variance median %.3f\n", median(guideRatio),
                mean(guideRatio), median(misRatio), mean(misRatio), median(oracleRatio), mean(oracleRatio), median(relBsdf));
  } catch (const InputError& e) {
    std::fprintf(stderr, "guide_quality: %s\n", e.what());
    return 2;
  }
  return 0;
}
