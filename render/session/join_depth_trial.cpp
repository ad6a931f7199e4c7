#include "render/session/join_depth_trial.h"

#include <algorithm>
#include <cmath>
#include "render/core/color.h"
#include "render/integrator/light_vertex_cache.h"
#include "render/session/tile_renderer.h"

namespace vpl {

JoinDepthTrial::JoinDepthTrial(int width, int height)
    : width_(size_t(std::max(width, 1))), pixels_(size_t(std::max(width, 0)) * size_t(std::max(height, 0))) {
  for (size_t c = 0; c < kCandidates.size(); ++c) {
    sum_[c].assign(pixels_, glm::vec3(0.0f));
    sum2_[c].assign(pixels_, glm::vec3(0.0f));
  }
}

void JoinDepthTrial::start(const Film& film) {
  const Image image = film.resolve();
  if (image.pixels.size() != pixels_) return;
  weight_.resize(pixels_);
  for (size_t i = 0; i < pixels_; ++i) {
    const glm::vec3 m = image.pixels[i];
    weight_[i] = 1.0f / (m * m + 0.01f);
  }
}

JoinDepthTrial::PassTargets JoinDepthTrial::beginPass(uint64_t slot, Film& image, LightVertexCache& joins) {
  joins.setJoinDepth(depthForNext(slot));
  if (!isTrialPass(slot) || !passFilm_) return {image};  // no films: the trial was never prepared
  passFilm_->clear();
  counterfactualFilm_->clear();
  return {*passFilm_, &*counterfactualFilm_, kCandidates[1]};
}

void JoinDepthTrial::endPass(uint64_t slot, Film& image, bool complete, const PassStats& stats,
                             const LightVertexCache& joins) {
  if (slot + 1 == kFirstPass && complete) {
    start(image);
    passFilm_.emplace(image.width(), image.height());
    counterfactualFilm_.emplace(image.width(), image.height());
  }
  if (!isTrialPass(slot) || !passFilm_) return;
  if (complete) {
    const double rays = double(stats.rays) + double(joins.rays());
    record(slot, {&*passFilm_, &*counterfactualFilm_}, {rays, rays - double(stats.raysPastCounterfactual)});
  }
  image.add(*passFilm_);
  if (decided_) {
    passFilm_.reset();
    counterfactualFilm_.reset();
  }
}

void JoinDepthTrial::record(uint64_t pass, const std::array<const Film*, kCandidates.size()>& films,
                            const std::array<double, kCandidates.size()>& rays) {
  if (!isTrialPass(pass) || decided_) return;
  for (const Film* film : films)
    if (size_t(film->width()) * size_t(film->height()) != pixels_) return;  // all or none of a pass
  for (size_t c = 0; c < kCandidates.size(); ++c) {
    const Image image = films[c]->resolve();
    for (size_t i = 0; i < pixels_; ++i) {
      const glm::vec3 v = image.pixels[i];
      sum_[c][i] += v;
      sum2_[c][i] += v * v;
    }
    rays_[c] += rays[c];
  }
  ++passes_;
  if (pass == kLastPass) decide();
}

void JoinDepthTrial::decide() {
  decided_ = true;
  if (weight_.size() != pixels_) return;  // start() was not called: keep every vertex
  if (passes_ < 2) return;  // no variance to compare: keep every vertex
  // Per candidate and group of rows (every kGroups-th row): the mean weighted variance.
  std::array<std::array<double, kGroups>, kCandidates.size()> groupSum{};
  std::array<size_t, kGroups> groupPixels{};
  for (size_t i = 0; i < pixels_; ++i) {
    const size_t g = (i / width_) % kGroups;
    ++groupPixels[g];
    for (size_t c = 0; c < kCandidates.size(); ++c) {
      const double n = passes_;
      for (int k = 0; k < 3; ++k) {
        const double sum = sum_[c][i][k], variance = std::max(0.0, (double(sum2_[c][i][k]) - sum * sum / n) / (n - 1.0));
        groupSum[c][g] += variance * weight_[i][k] / 3.0;
      }
    }
  }
  size_t best = 0;
  for (size_t c = 0; c < kCandidates.size(); ++c) {
    std::array<double, kGroups> means{};
    size_t used = 0;
    for (size_t g = 0; g < kGroups; ++g)
      if (groupPixels[g] > 0) means[used++] = groupSum[c][g] / double(groupPixels[g]);
    std::nth_element(means.begin(), means.begin() + used / 2, means.begin() + used);
    scores_[c] = means[used / 2] * rays_[c] / passes_;
    if (!std::isfinite(scores_[c])) scores_[c] = INFINITY;
    if (scores_[c] < (best == 0 ? kForecastMargin : 1.0) * scores_[best]) best = c;
  }
  chosen_ = kCandidates[best];
  // Only the decision needs the sums.
  for (size_t c = 0; c < kCandidates.size(); ++c) {
    std::vector<glm::vec3>().swap(sum_[c]);
    std::vector<glm::vec3>().swap(sum2_[c]);
  }
  std::vector<glm::vec3>().swap(weight_);
}

}  // namespace vpl
