// A discrete distribution over indices, proportional to non-negative weights (CDF + binary search).
#pragma once
#include <cstddef>
#include <span>
#include <vector>

namespace vpl {

class Distribution1D {
 public:
  Distribution1D() = default;
  // Negative, NaN and infinite weights count as 0.
  explicit Distribution1D(std::span<const float> weights);

  bool empty() const { return total_ <= 0.0; }
  size_t size() const { return pmf_.size(); }
  double total() const { return total_; }

  // An index with probability weight / total; *pmf gets that probability and *uRemapped a fresh
  // uniform in [0,1) recovered from u, so one random number can choose and then be reused.
  // Never returns an index of zero weight. Must not be called when empty().
  size_t sample(float u, float* pmf = nullptr, float* uRemapped = nullptr) const;
  float pmf(size_t i) const { return i < pmf_.size() ? pmf_[i] : 0.0f; }
  // The same within [begin, end) alone, by weight / the range's weight; the range must have weight.
  // Ranges of a row-major grid make a 2D table (GuideDistribution: rows by the sum of their range).
  size_t sampleRange(float u, size_t begin, size_t end, float* uRemapped = nullptr) const;
  // Sum of the normalised weights before index i (0 at 0, 1 at size()).
  double cdf(size_t i) const { return cdf_[i]; }

 private:
  std::vector<double> cdf_;  // cdf_[i] = sum of weights before i, normalised; size n + 1
  std::vector<float> pmf_;
  double total_ = 0.0;
};

}  // namespace vpl
