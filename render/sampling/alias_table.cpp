#include "render/sampling/alias_table.h"

#include <algorithm>
#include <cmath>

namespace vpl {

AliasTable::AliasTable(std::span<const float> weights) {
  const size_t n = weights.size();
  std::vector<double> w(n, 0.0);
  double sum = 0.0;
  size_t heaviest = 0;
  for (size_t i = 0; i < n; ++i) {
    const float x = weights[i];
    if (std::isfinite(x) && x > 0.0f) w[i] = double(x);
    sum += w[i];
    if (w[i] > w[heaviest]) heaviest = i;
  }
  if (!(sum > 0.0) || !std::isfinite(sum)) return;
  total_ = sum;
  bins_.resize(n);

  // Vose: scaled weights p_i = n w_i / sum average 1. Each bin under 1 is topped up from one over
  // 1, which then moves to the under list if it fell below 1 itself. Zero weights are paired
  // first (they sit on top of the stack), while the over list still certainly holds entries.
  std::vector<double> scaled(n);
  std::vector<uint32_t> under, over;
  under.reserve(n);
  over.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    scaled[i] = w[i] * double(n) / sum;
    bins_[i].pmf = float(w[i] / sum);
    if (scaled[i] >= 1.0) over.push_back(uint32_t(i));
  }
  for (size_t i = 0; i < n; ++i)
    if (scaled[i] < 1.0 && w[i] > 0.0) under.push_back(uint32_t(i));
  for (size_t i = 0; i < n; ++i)
    if (w[i] == 0.0) under.push_back(uint32_t(i));

  while (!under.empty() && !over.empty()) {
    const uint32_t small = under.back(), large = over.back();
    under.pop_back();
    bins_[small].keep = scaled[small];
    bins_[small].alias = large;
    scaled[large] = (scaled[large] + scaled[small]) - 1.0;
    if (scaled[large] < 1.0) {
      over.pop_back();
      under.push_back(large);
    }
  }
  // What is left is 1 up to rounding and keeps its whole bin. A zero weight can only be left by
  // rounding; it must still never be returned, so its bin goes to the heaviest entry.
  for (uint32_t i : over) bins_[i] = {1.0, i, bins_[i].pmf};
  for (uint32_t i : under) bins_[i] = w[i] > 0.0 ? Bin{1.0, i, bins_[i].pmf} : Bin{0.0, uint32_t(heaviest), 0.0f};
}

size_t AliasTable::sample(float u, float* pmf, float* uRemapped) const {
  const size_t n = bins_.size();
  const double x = std::clamp(double(u), 0.0, 1.0) * double(n);
  const size_t bin = std::min(size_t(x), n - 1);
  const double rest = std::min(x - double(bin), 1.0);  // in [0, 1)
  const Bin& b = bins_[bin];
  const bool kept = rest < b.keep;
  const size_t i = kept ? bin : b.alias;
  if (pmf) *pmf = bins_[i].pmf;
  // Two divisions, most callers' largest cost here: only for those who reuse the number.
  if (uRemapped) {
    const double remapped = kept ? rest / b.keep : (rest - b.keep) / (1.0 - b.keep);
    *uRemapped = float(std::clamp(remapped, 0.0, double(0x1.fffffep-1f)));
  }
  return i;
}

}  // namespace vpl
