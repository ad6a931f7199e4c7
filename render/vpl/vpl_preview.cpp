#include "render/vpl/vpl_preview.h"

#include <algorithm>
#include <cmath>
#include "render/core/color.h"
#include "render/core/stopwatch.h"

namespace vpl {

std::string PreviewSettings::validate() const {
  if (std::string e = vpl.validate(); !e.empty()) return e;
  if (std::string e = slices.validate(); !e.empty()) return e;
  if (std::string e = clustering.validate(); !e.empty()) return e;
  if (!(clampFraction >= 0.0f && clampFraction < 1.0f)) return "VPL clamp fraction must be in [0, 1)";
  if (clustersPerPass < 1) return "clusters per pass must be at least 1";
  if (!(pixelChoiceShare >= 0.0f && pixelChoiceShare <= 1.0f)) return "pixel choice share must be in [0, 1]";
  return {};
}

namespace {

bool vplVisible(const RenderScene& scene, const SurfaceHit& at, const Vpl& light, PathStats* stats = nullptr) {
  const glm::vec3 d = light.position - at.position;
  const float dist = glm::length(d);
  if (!(dist > 0.0f)) return false;
  const glm::vec3 wi = d / dist;
  if (glm::dot(wi, at.geometricNormal) <= 0.0f) return false;
  if (stats) ++stats->rays;
  return !scene.accel().occluded(spawnShadowRay(at, wi, dist));
}

// The light matrix entries LightSlice samples: VPL j seen from slice i's representative.
class SliceTransport final : public LightTransport {
 public:
  SliceTransport(const RenderScene& scene, const VplField& field) : scene_(scene), field_(field) {
    bsdfs_.reserve(field.tree.slices.size());
    for (const Slice& s : field.tree.slices) bsdfs_.push_back(scene.bsdf(field.gather.hits[s.representative]));
    for (const Vpl& v : field.vpls->vpls) lights_.push(v.position, v.normal, v.power());
  }
  float contribution(uint32_t slice, uint32_t vplIndex, bool visible) const override {
    const uint32_t g = field_.tree.slices[slice].representative;
    const SurfaceHit& hit = field_.gather.hits[g];
    const Vpl& light = field_.vpls->vpls[vplIndex];
    const float l = luminance(vplContribution(light, hit.position, bsdfs_[slice], field_.gather.wo[g], field_.minDistance));
    if (!(l > 0.0f) || !std::isfinite(l)) return 0.0f;
    if (visible && !vplVisible(scene_, hit, light)) return 0.0f;
    return l;
  }
  // The refinement's own row as diffuse transport: power x both cosines / clamped d^2. Exact BSDF
  // rows cost two BSDF evaluations per VPL and slice, most of LightSlice's time; the reduced rows
  // next to it keep the exact BSDFs and visibility. Plain arrays, so the loop vectorizes.
  void unoccludedRow(uint32_t slice, std::span<float> out) const override {
    const uint32_t g = field_.tree.slices[slice].representative;
    const glm::vec3 x = field_.gather.hits[g].position, n = field_.gather.hits[g].shadingNormal;
    const float clamp2 = field_.minDistance * field_.minDistance;
    const size_t count = std::min(out.size(), lights_.size());
    for (size_t j = 0; j < count; ++j) out[j] = lights_.transport(j, x, n, clamp2);
  }

 private:
  const RenderScene& scene_;
  const VplField& field_;
  std::vector<Bsdf> bsdfs_;
  PointLights lights_;  // the VPLs, weighted by power
};

// The slice whose clusters a preview pass uses at gather point g: g's, or one of its 31 nearest,
// drawn with weight (1 - d^2 / (36 r^2))^2 of the 6D distance d from g to each slice's representative
// (r^2: that slice's mean squared radius, so the weight ends 3 rms radii out, about 2.4 slice widths).
// Each slice's clusters approximate the VPL sum with their own bias; used only inside their slice,
// those biases showed as a mosaic of blocks that no number of passes removed. Weights that depend on g
// alone blend them smoothly, and a wide blend averages many slices' biases: with a blend of 2 rms radii
// over 8 slices, the blocks still showed on two_rooms' walls at 640x360 after 34 passes, and the
// relMSE at 2 s was 1.16-1.27x today's (docs/preview/preview.md). (Weighting from each pass's own hit
// instead, with the kd-tree's descent for its slice, put hits far from every gather point of their
// slice into it: fireflies, 1.3-2.5x the relMSE at 2 s on the Cornell boxes.)
uint32_t blendedSlice(const VplField& field, uint32_t g, float u) {
  constexpr int kCandidates = 32;  // SliceSettings::neighbours' default: no more are kept
  const SliceTree& tree = field.tree;
  const uint32_t own = tree.sliceOf[g];
  const std::span<const uint32_t> near = tree.neighboursOf(own);
  const int count = std::min<int>(kCandidates, int(near.size()));
  float weight[kCandidates];
  float total = 0.0f;
  for (int k = 0; k < count; ++k) {
    const Slice& t = tree.slices[near[size_t(k)]];
    const float d2 = embeddedDistance2(field.gather.points[g], field.gather.points[t.representative], tree.normalScale);
    const float f = std::max(0.0f, 1.0f - d2 / std::max(36.0f * t.radius2, 1e-30f));
    weight[k] = f * f;
    total += weight[k];
  }
  if (!(total > 0.0f)) return own;
  float target = u * total;
  for (int k = 0; k < count; ++k) {
    if (target < weight[k]) return near[size_t(k)];
    target -= weight[k];
  }
  return own;
}

// One emitter sample, unweighted: the preview has no BSDF-sampled light to combine it with.
glm::vec3 directLight(const RenderScene& scene, const SurfaceHit& surface, const Bsdf& bsdf, const glm::vec3& wo,
                      VertexSamples u, PathStats& stats) {
  const auto ls = scene.emitters().sampleStratified(surface.position, u.lightPoint(), [&] { return u.lightChoice(); });
  if (!ls) return glm::vec3(0.0f);
  const glm::vec3 f = bsdf.eval(wo, ls->wi);
  if (isBlack(f) || glm::dot(ls->wi, surface.geometricNormal) <= 0.0f) return glm::vec3(0.0f);
  ++stats.rays;
  return scene.accel().occluded(spawnShadowRay(surface, ls->wi, ls->distance)) ? glm::vec3(0.0f) : f * ls->radiance / ls->pdf;
}

// What a near-specular surface shows: its BSDF followed (a few bounces) to the first rough surface,
// which gets emission and direct light (light sampling alone cannot find a lobe a few degrees wide,
// and VPLs would light it in spikes).
glm::vec3 reflectedLight(const RenderScene& scene, SurfaceHit surface, Bsdf bsdf, glm::vec3 wo, PixelSampler& sampler,
                         PathStats& stats) {
  constexpr int kSpecularBounces = 8;
  const EmitterSet& emitters = scene.emitters();
  glm::vec3 L(0.0f), beta(1.0f);
  for (int bounce = 0; bounce < kSpecularBounces; ++bounce) {
    VertexSamples u(sampler, bounce);
    const auto next = bsdf.sample(wo, u.bsdfDirection());
    if (!next || glm::dot(next->wi, surface.geometricNormal) <= 0.0f) break;
    beta *= next->weight;
    const Ray ray = spawnRay(surface, next->wi);
    const RayHit hit = scene.accel().intersect(ray);
    ++stats.rays;
    if (!hit.valid()) return L + (emitters.hasSky() ? beta * emitters.sky() : glm::vec3(0.0f));
    surface = scene.surface(ray, hit);
    wo = -ray.direction;
    L += beta * emitters.emitted(surface, wo);
    bsdf = scene.bsdf(surface, wo);
    if (!bsdf.isNearSpecular()) return L + beta * directLight(scene, surface, bsdf, wo, VertexSamples(sampler, bounce + 1), stats);
  }
  return L;
}

}  // namespace

VplField buildVplField(const RenderScene& scene, const Camera& camera, std::shared_ptr<const VplSet> vpls,
                       const PreviewSettings& settings, const std::atomic<bool>* cancel) {
  VplField field;
  field.vpls = std::move(vpls);
  Stopwatch stopwatch;
  field.gather = gatherPrimaryHits(scene, camera);
  field.gatherSeconds = stopwatch.lap();
  const float diagonal = 2.0f * scene.radius();
  field.tree = buildSliceTree(field.gather.points, settings.slices, diagonal);
  field.sliceSeconds = stopwatch.lap();
  field.minDistance = settings.clampFraction * diagonal;
  const SliceTransport transport(scene, field);
  field.clusters = clusterLightSlice(field.vpls->vpls, field.gather.points, field.tree, transport, settings.clustering, cancel);
  field.rays = field.gather.rays + field.clusters.evaluations;

  // Which cluster a preview pass samples: by estimated contribution, with a defensive share so that
  // clusters whose representative is hidden from the slice's centre still get sampled elsewhere in it.
  field.clusterChoice.resize(field.clusters.slices.size());
  field.clusterPoints.resize(field.clusters.slices.size());
  for (size_t s = 0; s < field.clusters.slices.size(); ++s) {
    const auto& clusters = field.clusters.slices[s].clusters;
    std::vector<float> w(clusters.size());
    double sum = 0.0;
    for (const VplCluster& c : clusters) sum += c.estimate;
    const float mean = clusters.empty() ? 0.0f : float(sum / double(clusters.size()));
    for (size_t c = 0; c < clusters.size(); ++c)
      w[c] = mean > 0.0f ? clusters[c].estimate + 0.1f * mean : clusters[c].totalPower;
    field.clusterChoice[s] = Distribution1D(w);

    // Each cluster's weight is its estimate at the slice representative over its unoccluded
    // transport there, so that a pixel's weight (times the transport to its own hit) is the estimate
    // moved from the centre to the pixel: visibility, albedos and glossy lobes as seen at the centre.
    // A cluster the centre faces away from (a column's far side) takes the slice's mean ratio.
    ClusterPoints& points = field.clusterPoints[s];
    const SurfaceHit& centre = field.gather.hits[field.tree.slices[s].representative];
    for (const VplCluster& c : clusters) {  // weight 1 until the transport at the centre is known
      const Vpl& light = field.vpls->vpls[c.representative];
      points.push(light.position, light.normal, 1.0f);
    }
    const float clamp2 = field.minDistance * field.minDistance;
    std::vector<float> transport(clusters.size());
    double estimates = 0.0, unoccluded = 0.0;
    for (size_t c = 0; c < clusters.size(); ++c) {
      transport[c] = points.transport(c, centre.position, centre.shadingNormal, clamp2);
      if (transport[c] > 0.0f) {
        estimates += clusters[c].estimate;
        unoccluded += double(clusters[c].totalPower) * transport[c];
      }
    }
    const float meanRatio = unoccluded > 0.0 ? float(estimates / unoccluded) : 0.0f;
    constexpr float kUnoccludedShare = 3.0f;
    for (size_t c = 0; c < clusters.size(); ++c) {
      // Hidden from the centre is not hidden from every pixel (light through a slit, round a
      // column): the unoccluded weight at the mean ratio is added, three times the visible one.
      const float w = (transport[c] > 0.0f ? clusters[c].estimate / transport[c] : meanRatio * clusters[c].totalPower) +
                      kUnoccludedShare * meanRatio * clusters[c].totalPower;
      points.weight[c] = std::isfinite(w) ? w : 0.0f;
    }
  }
  return field;
}

PixelShaderFactory previewShader(const RenderScene& scene, const VplField& field, const PreviewSettings& settings) {
  const int m = settings.clustersPerPass;
  const float pixelShare = settings.pixelChoiceShare;
  return [&scene, &field, m, pixelShare](uint32_t, uint64_t) -> PixelShader {
    return [&scene, &field, m, pixelShare](const Ray& ray, uint64_t pixel, PixelSampler& sampler, PathStats& stats,
                                                   JoinDepthCounterfactual*) -> glm::vec3 {
      const EmitterSet& emitters = scene.emitters();
      const RayHit hit = scene.accel().intersect(ray);
      ++stats.rays;
      if (!hit.valid()) return emitters.hasSky() ? emitters.sky() : glm::vec3(0.0f);
      const SurfaceHit surface = scene.surface(ray, hit);
      const glm::vec3 wo = -ray.direction;
      glm::vec3 L = emitters.emitted(surface, wo);
      const Bsdf bsdf = scene.bsdf(surface, wo);
      if (bsdf.isNearSpecular()) return L + reflectedLight(scene, surface, bsdf, wo, sampler, stats);
      L += directLight(scene, surface, bsdf, wo, VertexSamples(sampler, 0), stats);

      // Indirect light: clusters of a slice at or next to the pixel's, sampled by estimated contribution.
      const int32_t g = pixel < field.gather.pixelGather.size() ? field.gather.pixelGather[pixel] : -1;
      if (g < 0) return L;
      const glm::vec2 choices = sampler.previewChoices();
      const uint32_t s = blendedSlice(field, uint32_t(g), choices.y);
      const Distribution1D& choice = field.clusterChoice[s];
      if (choice.empty()) return L;
      const auto& clusters = field.clusters.slices[s].clusters;
      // The picks are gathered first and their VPLs prefetched: with the slices blended, neighbouring
      // pixels draw from different slices' representatives, and each first touch of a VPL was a cache
      // miss that stalled the pass (a third of the shader's time on the interior at 1280x720).
      struct Pick {
        uint32_t cluster;
        float p;
      };
      static thread_local std::vector<Pick> picks;
      picks.clear();
      const auto pick = [&](size_t c, float p) {
        picks.push_back({uint32_t(c), p});
        const char* vpl = reinterpret_cast<const char*>(&field.vpls->vpls[clusters[c].representative]);
        for (size_t line = 0; line < sizeof(Vpl); line += 64) __builtin_prefetch(vpl + line);
      };
      // The light of cluster c drawn with probability p by each of the m picks.
      const auto add = [&](size_t c, float p) {
        const VplCluster& cluster = clusters[c];
        const Vpl& light = field.vpls->vpls[cluster.representative];
        const float repPower = light.power();
        if (!(repPower > 0.0f)) return;
        const glm::vec3 contribution =
            vplContribution(light, surface.position, bsdf, wo, field.minDistance) * (cluster.totalPower / repPower);
        if (!isBlack(contribution) && vplVisible(scene, surface, light, &stats)) L += contribution / (float(m) * p);
      };
      // Systematic sampling: the m picks sit at (i + u) / m of the CDF, one in each m-th of it. Each
      // pick alone is distributed by the pmf (so the sum stays unbiased), and u itself is
      // stratified across passes.
      const float u = choices.x;

      // Each cluster's probability: partly the slice's choice, mostly (pixelChoiceShare) its weight
      // moved to this very hit (ClusterPoints). A cluster close to the hit but far from the slice's
      // centre, or hidden from it, was otherwise a rare, bright draw: a sparkle. Past a few hundred
      // clusters (--clusters raised, or one slice of single VPLs) the sweep would cost more than the
      // shadow rays it saves, and the slice's choice decides alone.
      constexpr size_t kMaxSwept = 1024;
      const ClusterPoints& points = field.clusterPoints[s];
      float total = 0.0f;
      static thread_local std::vector<float> pmf;
      if (pixelShare > 0.0f && points.size() <= kMaxSwept) {
        pmf.resize(points.size());
        const float clamp2 = field.minDistance * field.minDistance;
        for (size_t c = 0; c < points.size(); ++c) pmf[c] = points.transport(c, surface.position, surface.shadingNormal, clamp2);
        float lanes[4] = {0.0f, 0.0f, 0.0f, 0.0f};  // the sum outside the loop above, so that it vectorizes
        size_t c = 0;
        for (; c + 4 <= points.size(); c += 4)
          for (int k = 0; k < 4; ++k) lanes[k] += pmf[c + size_t(k)];
        for (; c < points.size(); ++c) lanes[0] += pmf[c];
        total = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
      }
      if (!(total > 0.0f) || !std::isfinite(total)) {
        for (int i = 0; i < m; ++i) {
          float p = 0.0f;
          const size_t c = choice.sample((float(i) + u) / float(m), &p);
          pick(c, p);
        }
      } else {
        const float own = pixelShare / total, shared = 1.0f - pixelShare;
        for (size_t c = 0; c < points.size(); ++c) pmf[c] = pmf[c] * own + shared * choice.pmf(c);
        // One walk along the CDF serves the m sorted picks.
        size_t c = 0;
        float below = 0.0f;  // the CDF before cluster c
        for (int i = 0; i < m; ++i) {
          const float target = (float(i) + u) / float(m);
          while (c + 1 < points.size() && (below + pmf[c] <= target || pmf[c] <= 0.0f)) below += pmf[c++];
          while (c > 0 && !(pmf[c] > 0.0f)) below -= pmf[--c];  // rounding left the target past the last weight
          if (pmf[c] > 0.0f) pick(c, pmf[c]);
        }
      }
      for (const Pick& k : picks) add(k.cluster, k.p);
      return L;
    };
  };
}

PreviewSettings withAtMostSlices(const PreviewSettings& s, size_t pixels, int maxSlices) {
  PreviewSettings out = s;
  const size_t slices = size_t(std::max(1, maxSlices));
  out.slices.maxSliceSize = std::max<int>(s.slices.maxSliceSize, int(std::min<size_t>((pixels + slices - 1) / slices, 1u << 24)));
  return out;
}

PreviewSettings coarsePreviewSettings(const PreviewSettings& full, size_t pixels, const CoarsePreview& coarse) {
  PreviewSettings s = withAtMostSlices(full, pixels, coarse.slices);
  s.clustering.reducedRows = std::min(full.clustering.reducedRows, std::max(1, coarse.slices));
  s.clustersPerPass = std::clamp(coarse.clustersPerPass, 1, full.clustersPerPass);
  return s;
}

}  // namespace vpl
