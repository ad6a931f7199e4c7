#include "render/integrator/light_vertex_cache.h"

#include <algorithm>
#include <cmath>
#include <tbb/parallel_for.h>
#include "render/core/color.h"
#include "render/guide/emitter_guide.h"
#include "render/sampling/rng.h"
#include "render/vpl/light_walk.h"

namespace vpl {

int ConnectionSettings::pathsFor(int pixels, SamplingMode mode) const {
  if (mode == SamplingMode::Preview) return 0;  // no path tracing to join
  if (paths >= 0) return paths;
  if (!isGuided(mode)) return 0;
  return std::clamp(pixels / 32, 1024, 8192);
}

std::string ConnectionSettings::validate() const {
  if (paths < -1 || paths > 16'777'216) return "connection paths must be -1 (auto), 0 (off) or up to 16,777,216";
  if (joinsPerVertex < 1 || joinsPerVertex > LightVertexCache::kMaxJoinsPerVertex) return "joins per vertex must be between 1 and 16";
  if (joinDepth < kJoinDepthAuto || joinDepth > kMaxJoinDepth) return "join depth must be auto, -1 (every vertex), 0, 1 or 2";
  if (!(shadowRoulette >= 0.0f && shadowRoulette <= 100.0f)) return "join roulette share must be between 0 and 100";
  return {};
}

namespace {

struct PathVertices {
  std::vector<LightVertex> vertices;
  uint64_t rays = 0;
};

template <class Numbers>
void traceLightSubpath(const RenderScene& scene, const LightVertexCache& cache, const EmitterGuide* emitterGuide,
                       Numbers& numbers, int maxLength, PathVertices& out) {
  const auto e = startLightPath(scene, numbers);
  if (!e) return;
  // A light that no ray can hit (a point, a direction) has no strategy that reaches its start by
  // BSDF sampling: dVC starts at 0.
  float dVC = e->normal != glm::vec3(0.0f) ? connectionMis(glm::dot(e->normal, e->direction) / e->pdf) : 0.0f;
  float dVCM = 0.0f;
  float dVCNotJoins = dVC, dVCJoinTwoBack = 0.0f;  // dVC's parts (LightVertex)
  const auto onVertex = [&](const LightWalkVertex& v) {
    const float cosIn = std::abs(glm::dot(v.surface.geometricNormal, v.wIn));
    if (v.length == 1) {
      // Next-event estimation from here would have picked the start with a density of its own.
      const float direct = emitterGuide ? emitterGuide->nextEventPdfTimesCos(v.surface.position, *e)
                                        : scene.emitters().nextEventPdfTimesCos(v.surface.position, *e);
      dVCM = connectionMis(direct / (e->pdf * cosIn));
    } else {
      dVCM *= connectionMis(v.distance * v.distance) / connectionMis(cosIn);
    }
    dVC /= connectionMis(cosIn);
    dVCNotJoins /= connectionMis(cosIn);
    dVCJoinTwoBack /= connectionMis(cosIn);
    out.vertices.push_back({v.surface.position, v.surface.geometricNormal, v.wIn, v.throughput / cosIn, dVC, dVCM,
                            dVCNotJoins, dVCJoinTwoBack, v.length, 0u, v.bsdf});
    return true;
  };
  // Roulette is not counted in the MIS weights: they sum to 1 whatever it does.
  const auto onScatter = [&](const LightWalkVertex& v, const BsdfSample& s, float cosOut) {
    const float back = connectionMis(v.bsdf.pdf(s.wi, v.wIn)), forward = connectionMis(cosOut / s.pdf);
    dVC = forward * (dVC * back + dVCM);
    // dVCM is next-event estimation at length 1 and a join for length >= 2.
    dVCNotJoins = forward * (dVCNotJoins * back + (v.length == 1 ? dVCM : 0.0f));
    dVCJoinTwoBack = forward * (v.length == 1 ? 0.0f : dVCM);
    dVCM = connectionMis(1.0f / s.pdf) * cache.misFactor(v.surface.position);  // a join with its light end here
  };
  out.rays += walkLightPath(scene, numbers, *e, maxLength, onVertex, onScatter);
}

}  // namespace

void LightVertexCache::learnFromLastPass() {
  // What the joins of the last pass brought back joins the sums of the passes before it.
  double learnedTotal = 0.0, seenTotal = 0.0;
  for (size_t k = 0; k < size_t(kCells); ++k) {
    uint64_t sum = 0;
    for (size_t lane = 0; lane < kRecordLanes; ++lane) sum += pending(lane, k).exchange(0, std::memory_order_relaxed);
    learned_[k] += double(sum) / double(kFixedPoint);
    learnedTotal += learned_[k];
    seenTotal += seen_[k];
  }
  // A cell's expected pick rate over uniform choice's: its learned share over its share of the
  // vertices, mixed as chooseCells mixes them.
  const double learned = learnedShareFor(learnedTotal);
  for (size_t k = 0; k < size_t(kCells); ++k) {
    const double rate = learned > 0.0 && seen_[k] > 0.0 ? (learned_[k] / learnedTotal) / (seen_[k] / seenTotal) : 0.0;
    const double count = double(joinsPerVertex_) * ((1.0 - learned) + learned * rate);
    misFactor_[k] = connectionMis(float(std::min(count, double(kLargestMisCount))));
  }
}

void LightVertexCache::build(const RenderScene& scene, uint64_t seed, uint64_t pass, int paths, int maxLength,
                             bool stratified, const EmitterGuide* emitterGuide) {
  if (emitterGuide && !emitterGuide->active()) emitterGuide = nullptr;
  low_ = scene.data().boundsMin;
  perUnit_ = float(kCellsPerAxis) / glm::max(scene.data().boundsMax - low_, glm::vec3(1e-20f));
  learnFromLastPass();
  vertices_.clear();
  cellOf_.clear();
  cellStart_.clear();
  cellCount_.clear();
  cellCdf_.clear();
  cellScale_.clear();
  cellGuide_.clear();
  rays_ = 0;
  learnedShare_ = 0.0f;
  // No vertices where the tracer could not weight its joins (PathTracer ignores the cache there).
  if (paths <= 0 || maxLength <= 0 || !scene.emitters().supportsConnections() || scene.emitters().empty()) return;
  constexpr int kBatch = 256;
  const int batches = (paths + kBatch - 1) / kBatch;
  std::vector<PathVertices> results(static_cast<size_t>(batches));
  const uint64_t passKey = mix64(mix64(seed ^ 0x6c76635f70617468ull) ^ pass);
  // The pass's paths are the samples of one stream of PixelSampler's (an index no pixel has).
  constexpr uint64_t kLightPathStream = ~uint64_t(0);
  // Batches in parallel, appended in path order: the cache is the same for any thread count.
  tbb::parallel_for(0, batches, [&](int b) {
    const int end = std::min(paths, (b + 1) * kBatch);
    for (int i = b * kBatch; i < end; ++i) {
      if (stratified) {
        StratifiedWalkNumbers numbers{PixelSampler(passKey, kLightPathStream, uint64_t(i))};
        traceLightSubpath(scene, *this, emitterGuide, numbers, maxLength, results[size_t(b)]);
      } else {
        Rng rng = Rng::hashed(mix64(passKey ^ uint64_t(i)));
        RandomWalkNumbers numbers{rng};
        traceLightSubpath(scene, *this, emitterGuide, numbers, maxLength, results[size_t(b)]);
      }
    }
  });
  std::vector<std::vector<LightVertex>> batchVertices;
  batchVertices.reserve(results.size());
  for (PathVertices& r : results) {
    batchVertices.push_back(std::move(r.vertices));
    rays_ += r.rays;
  }
  sortIntoCells(batchVertices);
  if (vertices_.empty()) return;
  chooseCells(paths);
}

void LightVertexCache::sortIntoCells(std::vector<std::vector<LightVertex>>& batches) {
  std::vector<uint32_t> count(kCells, 0);
  size_t total = 0;
  for (std::vector<LightVertex>& batch : batches) {
    total += batch.size();
    for (LightVertex& v : batch) {
      v.cell = cellOf(v.position);
      ++count[v.cell];
    }
  }
  for (size_t k = 0; k < size_t(kCells); ++k) seen_[k] += double(count[k]);
  // A counting sort of the batches straight into vertices_, stable: within a cell, path order.
  std::vector<uint32_t> next(kCells, 0);
  for (uint32_t k = 0, start = 0; k < uint32_t(kCells); start += count[k++]) {
    next[k] = start;
    if (count[k] == 0) continue;
    cellOf_.push_back(k);
    cellStart_.push_back(start);
    cellCount_.push_back(count[k]);
  }
  vertices_.resize(total);
  for (std::vector<LightVertex>& batch : batches)
    for (LightVertex& v : batch) vertices_[next[v.cell]++] = std::move(v);
}

void LightVertexCache::chooseCells(int paths) {
  double learnedTotal = 0.0;
  for (const uint32_t k : cellOf_) learnedTotal += learned_[k];
  const double learned = learnedShareFor(learnedTotal);
  learnedShare_ = float(learned);
  const double count = double(vertices_.size());
  double cumulative = 0.0;
  for (size_t c = 0; c < cellOf_.size(); ++c) {
    cumulative += (1.0 - learned) * double(cellCount_[c]) / count;
    if (learned > 0.0) cumulative += learned * learned_[cellOf_[c]] / learnedTotal;
    cellCdf_.push_back(float(cumulative));
  }
  cellCdf_.back() = 1.0f;
  cellGuide_.resize(kGuidePerCell * cellCdf_.size());
  for (size_t b = 0, c = 0; b < cellGuide_.size(); ++b) {
    const float low = float(double(b) / double(cellGuide_.size()));
    while (c + 1 < cellCdf_.size() && cellCdf_[c] <= low) ++c;
    cellGuide_[b] = uint32_t(c);
  }
  // The scale from the probability the float cumulative sums actually give each cell.
  for (size_t c = 0; c < cellOf_.size(); ++c) {
    const double width = double(cellCdf_[c]) - (c > 0 ? double(cellCdf_[c - 1]) : 0.0);
    cellScale_.push_back(width > 0.0 ? float(double(cellCount_[c]) / (width * double(paths) * double(joinsPerVertex_))) : 0.0f);
  }
}

}  // namespace vpl
