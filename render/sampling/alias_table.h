// A discrete distribution over indices, proportional to non-negative weights, sampled in O(1)
// whatever the number of entries: Walker's alias method with Vose's construction (O(n)). Same
// interface as Distribution1D, which needs a binary search (O(log n)) per sample.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace vpl {

class AliasTable {
 public:
  AliasTable() = default;
  // Negative, NaN and infinite weights count as 0.
  explicit AliasTable(std::span<const float> weights);

  bool empty() const { return total_ <= 0.0; }
  size_t size() const { return bins_.size(); }
  double total() const { return total_; }

  // An index with probability weight / total; *pmf gets that probability and *uRemapped a fresh
  // uniform in [0,1) recovered from u, so one random number can choose and then be reused.
  // Never returns an index of zero weight. Must not be called when empty().
  size_t sample(float u, float* pmf = nullptr, float* uRemapped = nullptr) const;
  float pmf(size_t i) const { return i < bins_.size() ? bins_[i].pmf : 0.0f; }

 private:
  // u picks bin floor(u n) uniformly; within it, the rest of u below `keep` keeps the bin's own
  // index, above it takes `alias`.
  struct Bin {
    double keep = 1.0;
    uint32_t alias = 0;
    float pmf = 0.0f;  // weight / total of this index (not of the bin)
  };
  std::vector<Bin> bins_;
  double total_ = 0.0;
};

}  // namespace vpl
