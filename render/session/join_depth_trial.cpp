#include "render/session/join_depth_trial.h"

#include <algorithm>
#include <cmath>
#include "render/core/color.h"
#include "render/integrator/light_vertex_cache.h"

namespace vpl {

JoinDepthTrial::JoinDepthTrial(int width, int height)
    : width_(size_t(std::max(width, 1))), pixels_(size_t(std::max(width, 0)) * size_t(std::max(height, 0))) {
  for (size_t c = 0; c < kCandidates.size(); ++c) {
    sum_[c].assign(pixels_, 0.0);
    sum2_[c].assign(pixels_, 0.0);
  }
}

void JoinDepthTrial::start(const Film& film) {
  const Image image = film.resolve();
  if (image.pixels.size() != pixels_) return;
  weight_.resize(pixels_);
  for (size_t i = 0; i < pixels_; ++i) {
    const double m = luminance(image.pixels[i]);
    weight_[i] = 1.0 / (m * m + 0.01);
  }
}

Film& JoinDepthTrial::beginPass(uint64_t slot, Film& image, LightVertexCache& joins) {
  joins.setJoinDepth(depthForNext(slot));
  if (!isTrialPass(slot) || !passFilm_) return image;  // no film: the trial was never prepared
  passFilm_->clear();
  return *passFilm_;
}

void JoinDepthTrial::endPass(uint64_t slot, Film& image, bool complete, double cameraRays, const LightVertexCache& joins) {
  if (slot + 1 == kFirstPass && complete) {
    start(image);
    passFilm_.emplace(image.width(), image.height());
  }
  if (!isTrialPass(slot) || !passFilm_) return;
  if (complete) record(slot, *passFilm_, cameraRays + double(joins.rays()));
  image.add(*passFilm_, kTrialPassWeight);
  if (decided_) passFilm_.reset();
}

int JoinDepthTrial::depthFor(uint64_t pass) const {
  if (isTrialPass(pass)) return kCandidates[candidateOf(pass)];
  return decided_ ? chosen_ : kCandidates[0];
}

void JoinDepthTrial::record(uint64_t pass, const Film& passFilm, double rays) {
  if (!isTrialPass(pass) || decided_) return;
  const size_t c = candidateOf(pass);
  const Image image = passFilm.resolve();
  if (image.pixels.size() != pixels_) return;
  for (size_t i = 0; i < pixels_; ++i) {
    const double l = luminance(image.pixels[i]);
    sum_[c][i] += l;
    sum2_[c][i] += l * l;
  }
  rays_[c] += rays;
  ++passes_[c];
  if (pass == kLastPass) decide();
}

void JoinDepthTrial::decide() {
  decided_ = true;
  if (weight_.size() != pixels_) return;  // start() was not called: keep every vertex
  for (int n : passes_)
    if (n < 2) return;  // no variance to compare: keep every vertex
  // Per candidate and group of rows (every kGroups-th row): the mean weighted variance.
  std::array<std::array<double, kGroups>, kCandidates.size()> groupSum{};
  std::array<size_t, kGroups> groupPixels{};
  for (size_t i = 0; i < pixels_; ++i) {
    const size_t g = (i / width_) % kGroups;
    ++groupPixels[g];
    for (size_t c = 0; c < kCandidates.size(); ++c) {
      const double n = passes_[c];
      const double variance = std::max(0.0, (sum2_[c][i] - sum_[c][i] * sum_[c][i] / n) / (n - 1.0));
      groupSum[c][g] += variance * weight_[i];
    }
  }
  size_t best = 0;
  for (size_t c = 0; c < kCandidates.size(); ++c) {
    std::array<double, kGroups> means{};
    size_t used = 0;
    for (size_t g = 0; g < kGroups; ++g)
      if (groupPixels[g] > 0) means[used++] = groupSum[c][g] / double(groupPixels[g]);
    std::nth_element(means.begin(), means.begin() + used / 2, means.begin() + used);
    scores_[c] = means[used / 2] * rays_[c] / passes_[c];
    if (!std::isfinite(scores_[c])) scores_[c] = INFINITY;
    if (scores_[c] < scores_[best]) best = c;
  }
  chosen_ = kCandidates[best];
  // Only the decision needs the sums.
  for (size_t c = 0; c < kCandidates.size(); ++c) {
    std::vector<double>().swap(sum_[c]);
    std::vector<double>().swap(sum2_[c]);
  }
  std::vector<double>().swap(weight_);
}

}  // namespace vpl
