#include "tests/unit/pixel_agreement.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <gtest/gtest.h>

namespace vpl::test {

BatchEstimate estimateFromBatches(const std::vector<Image>& batches) {
  BatchEstimate e;
  if (batches.empty()) return e;
  e.width = batches[0].width;
  e.height = batches[0].height;
  e.batches = int(batches.size());
  const size_t n = batches[0].pixels.size();
  const double b = double(batches.size());
  e.mean.assign(n, glm::dvec3(0.0));
  e.variance.assign(n, glm::dvec3(0.0));
  std::vector<glm::dvec3> imageMeans;
  for (const Image& image : batches) {
    glm::dvec3 sum(0.0);
    for (size_t i = 0; i < n; ++i) {
      e.mean[i] += glm::dvec3(image.pixels[i]) / b;
      sum += glm::dvec3(image.pixels[i]);
    }
    imageMeans.push_back(sum / double(n));
  }
  for (const Image& image : batches)
    for (size_t i = 0; i < n; ++i) {
      const glm::dvec3 d = glm::dvec3(image.pixels[i]) - e.mean[i];
      e.variance[i] += d * d / ((b - 1.0) * b);
    }
  for (const glm::dvec3& m : imageMeans) e.imageMean += m / b;
  for (const glm::dvec3& m : imageMeans) e.imageMeanVariance += (m - e.imageMean) * (m - e.imageMean) / ((b - 1.0) * b);
  return e;
}

Agreement compareEstimates(const BatchEstimate& a, const BatchEstimate& b) {
  Agreement r;
  double worstZ = -1.0;
  double sumZ = 0.0, sumZ2 = 0.0;
  int beyond4 = 0;
  for (size_t i = 0; i < a.mean.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double diff = a.mean[i][c] - b.mean[i][c];
      const double variance = a.variance[i][c] + b.variance[i][c];
      double z;
      if (variance > 0.0) {
        z = diff / std::sqrt(variance);
      } else if (std::abs(diff) <= 1e-6 * std::max(std::abs(a.mean[i][c]), 1e-6)) {
        continue;  // noise-free in both (black, or the sky seen straight) and equal
      } else {
        ++r.exactMismatches;
        z = INFINITY;
      }
      ++r.samples;
      if (std::isfinite(z)) sumZ += z;
      sumZ2 += std::min(z * z, 25.0);
      beyond4 += std::abs(z) > 4.0;
      if (std::abs(z) > worstZ) {
        worstZ = std::abs(z);
        std::ostringstream s;
        s << "worst pixel (" << i % size_t(a.width) << ", " << i / size_t(a.width) << ") channel " << c << ": " << a.mean[i][c]
          << " against " << b.mean[i][c] << ", z " << z;
        r.worst = s.str();
      }
    }
  for (int c = 0; c < 3; ++c) {
    const double variance = a.imageMeanVariance[c] + b.imageMeanVariance[c];
    const double diff = a.imageMean[c] - b.imageMean[c];
    const double z = variance > 0.0 ? std::abs(diff) / std::sqrt(variance) : (diff == 0.0 ? 0.0 : INFINITY);
    r.imageZ = std::max(r.imageZ, z);
    const double scale = std::max(std::abs(b.imageMean[c]), 1e-12);
    r.imageRelDiff[c] = diff / scale;
    r.imageRelError[c] = std::sqrt(variance) / scale;
  }
  if (r.samples > 0) {
    r.meanZ = sumZ / r.samples;
    r.meanZ2 = sumZ2 / r.samples;
    r.beyond4 = double(beyond4) / r.samples;
  }
  return r;
}

// The bounds, for estimates of 12 or more batches each (z is then about Student t with 22 to 30
// degrees of freedom by Welch's rule):
// - image mean: P(|t_22| > 5) = 5e-5 per channel.
// - mean z: counting pixels, not channels (a pixel's channels share its paths), 16 x 12 independent
//   t variables give sd(mean z) = 0.08; 0.4 is five of those. Skewed pixels (rare bright paths:
//   the batch variance is small exactly when the batch mean is low) pull mean z below 0: guided
//   modes measured -0.25 to +0.09 against brdf on the built-in scenes. 32 x 24 images can use 0.25.
// - mean of z^2 (capped at 25): its expectation is 1.07-1.10 for those t; the channels of one path
//   and the pixels of one Metropolis chain are correlated, so its spread is measured, not assumed:
//   over the 11 mode-scene pairs of test_guided_modes that sample glossy lobes by MIS or not at all,
//   and brdf against brdf, it ranged over 0.84-1.21 (16 x 12 pixels, 16 batches of 256 spp);
//   1.6 is four of those spreads above the expectation.
// - |z| > 4: 0.03-0.05 % of t_22..t_30 samples; 2 % leaves room for a few pixels whose batch
//   variance came out too small.
// At those budgets brdf against itself 5 % brighter in a tenth of the pixels reaches 1.65, and 3 %
// brighter and darker in alternate rows (a bias the image mean cannot see) 2.30.
void expectAgreement(const Agreement& r, const std::string& what, const AgreementBounds& bounds) {
  std::printf("%s: %d pixel-channels, image mean %+.3f/%+.3f/%+.3f %% apart (standard error %.3f %%, |z| %.2f), mean z "
              "%+.3f, mean z^2 %.3f, beyond 4 sigma %.2f %%, %s\n",
              what.c_str(), r.samples, 100.0 * r.imageRelDiff.x, 100.0 * r.imageRelDiff.y, 100.0 * r.imageRelDiff.z,
              100.0 * std::max({r.imageRelError.x, r.imageRelError.y, r.imageRelError.z}), r.imageZ, r.meanZ, r.meanZ2,
              100.0 * r.beyond4, r.worst.c_str());
  EXPECT_GT(r.samples, 0) << what << ": nothing to compare";
  for (int c = 0; c < 3; ++c)
    EXPECT_LT(std::abs(r.imageRelDiff[c]), bounds.imageZ * r.imageRelError[c] + bounds.imageFloor)
        << what << ": the image means of channel " << c << " differ by " << 100.0 * r.imageRelDiff[c] << " % (standard error "
        << 100.0 * r.imageRelError[c] << " %)";
  EXPECT_LT(std::abs(r.meanZ), bounds.meanZ) << what << ": a bias of one sign over the image; " << r.worst;
  EXPECT_LT(r.meanZ2, bounds.meanZ2) << what << ": pixels differ by more than their noise; " << r.worst;
  EXPECT_LT(r.beyond4, bounds.beyond4) << what << ": too many pixels beyond 4 sigma; " << r.worst;
  EXPECT_EQ(r.exactMismatches, 0) << what << ": noise-free pixels differ; " << r.worst;
}

}  // namespace vpl::test
