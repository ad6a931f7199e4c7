#include "render/guide/selection_learner.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vpl {

void SelectionLearner::TileLog::add(int cachePoint, float bsdfPdf, float guidePdf, float drawnPdf, float estimate) {
  if (!(drawnPdf > 0.0f) || !std::isfinite(estimate) || !std::isfinite(drawnPdf) || !(estimate >= 0.0f)) return;
  if (entries_.empty() || entries_.back().cachePoint != cachePoint) {
    auto it = entries_.begin();
    while (it != entries_.end() && it->cachePoint != cachePoint) ++it;
    if (it == entries_.end()) {
      entries_.push_back(Entry{cachePoint, 0, {}});
    } else {
      std::iter_swap(it, entries_.end() - 1);  // keep the latest at the back: neighbours repeat
    }
  }
  Entry& e = entries_.back();
  ++e.samples;
  const double squared = double(estimate) * double(estimate) * double(drawnPdf);
  for (size_t k = 0; k < kCount; ++k) {
    const double candidate = double(kCandidates[k]) * bsdfPdf + (1.0 - double(kCandidates[k])) * guidePdf;
    e.moment[k] += candidate > 0.0 ? squared / candidate
                                   : (squared > 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
  }
}

SelectionLearner::SelectionLearner(size_t cachePoints, int tiles, float prior)
    : probability_(cachePoints, prior), samples_(cachePoints, 0), moment_(cachePoints), tiles_(size_t(tiles)) {}

void SelectionLearner::update() {
  for (TileLog& tile : tiles_) {
    for (const TileLog::Entry& e : tile.entries_) {
      const size_t c = size_t(e.cachePoint);
      samples_[c] += e.samples;
      for (size_t k = 0; k < kCount; ++k) moment_[c][k] += e.moment[k];
    }
    tile.entries_.clear();
  }
  for (size_t c = 0; c < probability_.size(); ++c) {
    if (samples_[c] < kMinSamples) continue;
    size_t best = 0;
    for (size_t k = 1; k < kCount; ++k)
      if (moment_[c][k] < moment_[c][best]) best = k;
    // The most BSDF whose moment is within the margin of the least (see kStratifiedMargin).
    const double least = moment_[c][best];
    for (size_t k = kCount - 1; k > best; --k)
      if (moment_[c][k] <= (1.0 + kStratifiedMargin) * least) {
        best = k;
        break;
      }
    if (moment_[c][kCount - 1] <= (1.0 + kBsdfOnlyMargin) * least) best = kCount - 1;  // see kBsdfOnlyMargin
    if (std::isfinite(moment_[c][best])) probability_[c] = kCandidates[best];
  }
}

double SelectionLearner::guideGain() const {
  double chosen = 0.0, bsdfAlone = 0.0;
  for (size_t c = 0; c < probability_.size(); ++c) {
    if (samples_[c] < kMinSamples) continue;
    const auto k = size_t(std::find(kCandidates.begin(), kCandidates.end(), probability_[c]) - kCandidates.begin());
    if (k == kCount || !std::isfinite(moment_[c][k]) || !std::isfinite(moment_[c][kCount - 1])) continue;
    chosen += moment_[c][k];
    bsdfAlone += moment_[c][kCount - 1];
  }
  return bsdfAlone > 0.0 ? chosen / bsdfAlone : -1.0;
}

double SelectionLearner::meanLearnedProbability() const {
  double sum = 0.0;
  size_t n = 0;
  for (size_t c = 0; c < probability_.size(); ++c)
    if (samples_[c] >= kMinSamples) {
      sum += probability_[c];
      ++n;
    }
  return n ? sum / double(n) : -1.0;
}

}  // namespace vpl
