#include "render/guide/guide_learner.h"

#include <cmath>
#include <tbb/parallel_for.h>

namespace vpl {

void GuideLearner::TileLog::add(int cachePoint, const glm::vec3& wi, float value) {
  if (!std::isfinite(value) || !(value >= 0.0f)) value = 0.0f;  // counts as a sample that found nothing
  records_.push_back({cachePoint, uint16_t(GuideDistribution::cellOf(wi)), value});
}

GuideLearner::GuideLearner(const GuideField& field, int tiles, bool vplPrior, float defensive)
    : field_(field), vplPrior_(vplPrior), defensive_(defensive), sums_(field.size()), samples_(field.size(), 0),
      tiles_(size_t(tiles)) {
  current_.reserve(field.size());
  const GuideSettings& s = field.settings();
  for (size_t c = 0; c < field.size(); ++c)
    current_.push_back(vplPrior ? field.point(int(c)).distribution
                                : GuideDistribution(std::vector<GuideRepresentative>{}, 1.0f, defensive_, s.bilinear));
}

GuideDistribution GuideLearner::blend(int c) const {
  const auto& sums = sums_[size_t(c)];
  double learnedTotal = 0.0;
  for (double s : sums) learnedTotal += s;
  const GuideDistribution& prior = field_.point(c).distribution;
  const bool hasPrior = vplPrior_ && !prior.uniform();
  if (!(learnedTotal > 0.0)) return hasPrior ? prior : current_[size_t(c)];  // nothing found yet: no evidence against
  const double n = double(samples_[size_t(c)]);
  const double lambda = vplPrior_ ? n / (n + kPriorSamples) : 1.0;
  std::vector<float> weights(kCells);
  for (int f = 0; f < kCells; ++f) {
    const double priorShare = hasPrior ? prior.cellShare(f) : 1.0 / kCells;
    weights[size_t(f)] = float((1.0 - lambda) * priorShare + lambda * sums[size_t(f)] / learnedTotal);
  }
  // Bilinear, the prior's shares are already the interpolated guide's, so the blend is interpolated
  // once more: the prior's part a cell wider than the learned part.
  return GuideDistribution(weights, defensive_, field_.settings().bilinear);
}

void GuideLearner::update() {
  std::vector<uint8_t> touched(current_.size(), 0);
  for (TileLog& tile : tiles_) {
    for (const TileLog::Record& r : tile.records_) {
      sums_[size_t(r.cachePoint)][r.cell] += double(r.value);
      ++samples_[size_t(r.cachePoint)];
      touched[size_t(r.cachePoint)] = 1;
    }
    tile.records_.clear();
  }
  tbb::parallel_for(size_t(0), current_.size(), [&](size_t c) {
    if (touched[c]) current_[c] = blend(int(c));
  });
}

double GuideLearner::meanLearnedShare() const {
  if (samples_.empty()) return 0.0;
  double sum = 0.0;
  for (uint32_t n : samples_) sum += vplPrior_ ? double(n) / (double(n) + kPriorSamples) : (n > 0 ? 1.0 : 0.0);
  return sum / double(samples_.size());
}

}  // namespace vpl
