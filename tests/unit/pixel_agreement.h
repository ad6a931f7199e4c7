// Per-pixel agreement of two estimators, each given as independent batches (renders with distinct
// seeds, so every source of randomness, the VPLs and the guide included, differs between batches).
// Image means and relMSE hide a bias that cancels across pixels or lives in a few of them; a
// per-pixel z-score does not.
#pragma once
#include <string>
#include <vector>
#include <glm/glm.hpp>
#include "render/film/image.h"

namespace vpl::test {

// Per pixel and channel: the mean of the batches and the squared standard error of that mean.
struct BatchEstimate {
  int width = 0, height = 0, batches = 0;
  std::vector<glm::dvec3> mean, variance;  // variance of the mean, not of one batch
  glm::dvec3 imageMean{0.0}, imageMeanVariance{0.0};  // the same for the image's mean, from the
                                                      // batches' image means: exact whatever the
                                                      // correlation between pixels
};
BatchEstimate estimateFromBatches(const std::vector<Image>& batches);

// z = (a - b) / sqrt(se_a^2 + se_b^2) over every pixel and channel where either estimate varies;
// where neither varies, the two must be equal (else the pixel counts as beyond every bound).
struct Agreement {
  int samples = 0;          // pixel-channels that entered the statistics
  double meanZ = 0.0;       // a bias of one sign over many pixels
  double imageZ = 0.0;      // the largest |z| of the image mean's channels: a bias shared by the pixels
  glm::dvec3 imageRelDiff{0.0}, imageRelError{0.0};  // per channel: (a - b) / b of the image means,
                                                     // and the standard error of that
  double meanZ2 = 0.0;      // z^2 capped at 25: ~1 (a little above: Student t) without bias; a bias
                            // of either sign in many pixels raises it, even one that cancels out
  double beyond4 = 0.0;     // fraction of |z| > 4: a bias in a few pixels
  int exactMismatches = 0;  // noise-free pixel-channels that differ
  std::string worst;        // the largest |z| with its pixel, for failure messages
};
Agreement compareEstimates(const BatchEstimate& a, const BatchEstimate& b);

// What two unbiased estimators stay within (the derivation and its confidence in pixel_agreement.cpp).
struct AgreementBounds {
  double imageZ = 5.0, meanZ2 = 1.6, beyond4 = 0.02, meanZ = 0.4;
  // A relative difference of the image means allowed beyond imageZ standard errors: zero between
  // two modes of this renderer; between two renderers, the differences of their models.
  double imageFloor = 0.0;
};
// For an estimator with heavy tails (guide-only sampling of glossy lobes: rare large weights), whose
// batch variance is itself underestimated in most runs: on cornell_glossy up to 1.54 and 1.2 %.
constexpr AgreementBounds kHeavyTailBounds{5.0, 2.0, 0.03};

// EXPECTs every bound, with `what` and the figures in the message; prints the figures.
void expectAgreement(const Agreement& agreement, const std::string& what, const AgreementBounds& bounds = {});

}  // namespace vpl::test
