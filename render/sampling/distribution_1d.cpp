#include "render/sampling/distribution_1d.h"

#include <algorithm>
#include <cmath>

namespace vpl {

Distribution1D::Distribution1D(std::span<const float> weights) {
  const size_t n = weights.size();
  cdf_.assign(n + 1, 0.0);
  pmf_.assign(n, 0.0f);
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const float w = weights[i];
    if (std::isfinite(w) && w > 0.0f) sum += double(w);
    cdf_[i + 1] = sum;
  }
  total_ = sum;
  if (!(sum > 0.0)) return;
  for (size_t i = 0; i < n; ++i) pmf_[i] = float((cdf_[i + 1] - cdf_[i]) / sum);
  for (size_t i = 1; i <= n; ++i) cdf_[i] /= sum;
  cdf_[n] = 1.0;
}

size_t Distribution1D::sample(float u, float* pmf, float* uRemapped) const {
  // First index whose upper CDF bound exceeds u; zero-weight entries have empty intervals and are skipped.
  const double x = std::clamp(double(u), 0.0, 1.0);
  auto it = std::upper_bound(cdf_.begin() + 1, cdf_.end(), x);
  size_t i = it == cdf_.end() ? pmf_.size() - 1 : size_t(it - cdf_.begin()) - 1;
  while (pmf_[i] <= 0.0f && i > 0) --i;  // only reachable through rounding at the very top
  while (pmf_[i] <= 0.0f && i + 1 < pmf_.size()) ++i;
  if (pmf) *pmf = pmf_[i];
  if (uRemapped) {
    const double width = cdf_[i + 1] - cdf_[i];
    *uRemapped = float(std::clamp(width > 0.0 ? (x - cdf_[i]) / width : 0.0, 0.0, double(0x1.fffffep-1f)));
  }
  return i;
}

}  // namespace vpl
