// The learned MIS selection probability (render/guide/selection_learner.h): it must find the
// mixture of least variance from samples drawn with another, keep the prior without evidence, and
// not depend on how samples were spread over tiles. Its unbiasedness in images is GuidedModes' job.
#include <cmath>
#include <numbers>
#include <gtest/gtest.h>
#include "render/guide/guide_distribution.h"
#include "render/guide/selection_learner.h"
#include "render/sampling/rng.h"
#include "render/sampling/warps.h"

namespace vpl {
namespace {

constexpr float kDeg = std::numbers::pi_v<float> / 180.0f;

// A cache point's setting: the BSDF is a cosine lobe about +z, the guide a 10-degree cone about a
// direction 50 degrees off. The integrand is either the guide's shape (light from a small source)
// or the cosine's (light from everywhere), times 3.
struct Setting {
  GuideDistribution guide;
  glm::vec3 axis;
  Setting() : axis(glm::normalize(glm::vec3(std::sin(50 * kDeg), 0.0f, std::cos(50 * kDeg)))) {
    guide = GuideDistribution({GuideRepresentative{axis, 1.0f, 0.0f}}, 10.0f * kDeg, 0.05f);
  }
  float bsdfPdf(const glm::vec3& w) const { return w.z > 0.0f ? w.z / std::numbers::pi_v<float> : 0.0f; }
};

// Draws n directions from the mixture with BSDF probability `drawn` and logs them to `log`.
void logSamples(const Setting& s, bool lightLikeTheGuide, float drawn, int n, uint64_t seed, SelectionLearner::TileLog& log) {
  Rng rng(seed);
  for (int i = 0; i < n; ++i) {
    const glm::vec3 w = rng.uniform() < drawn ? sampleCosineHemisphere(rng.uniform2()) : s.guide.sample(rng.uniform2());
    const float pb = s.bsdfPdf(w), pg = s.guide.pdf(w);
    const float q = drawn * pb + (1.0f - drawn) * pg;
    const float integrand = 3.0f * (lightLikeTheGuide ? (w.z > 0.0f ? pg : 0.0f) : pb);
    log.add(0, pb, pg, q, integrand / q);
  }
}

TEST(SelectionLearner, PicksTheGuideWhereTheLightFollowsItAndTheBsdfWhereItDoesNot) {
  const Setting s;
  for (const float drawn : {0.1f, 0.5f, 1.0f}) {
    SelectionLearner guideLike(1, 1, 0.5f), bsdfLike(1, 1, 0.5f);
    logSamples(s, true, drawn, 20000, 1, guideLike.tileLog(0));
    logSamples(s, false, drawn, 20000, 2, bsdfLike.tileLog(0));
    guideLike.update();
    bsdfLike.update();
    EXPECT_EQ(guideLike.bsdfProbability(0), SelectionLearner::kCandidates.front()) << "drawn with " << drawn;
    EXPECT_EQ(bsdfLike.bsdfProbability(0), 1.0f) << "drawn with " << drawn;
    EXPECT_NEAR(guideLike.meanLearnedProbability(), SelectionLearner::kCandidates.front(), 1e-6);
  }
}

// The forecast of what the learned probabilities take off the BSDF's second moment (GuideSwitch reads
// it): about the guide's own gain where the light follows the guide, 1 where it follows the BSDF,
// -1 before any cache point has enough samples.
TEST(SelectionLearner, ForecastsWhatTheGuideGains) {
  const Setting s;
  SelectionLearner guideLike(1, 1, 0.5f), bsdfLike(1, 1, 0.5f), early(1, 1, 0.5f);
  logSamples(s, true, 0.5f, 20000, 1, guideLike.tileLog(0));
  logSamples(s, false, 0.5f, 20000, 2, bsdfLike.tileLog(0));
  logSamples(s, true, 0.5f, int(SelectionLearner::kMinSamples) - 1, 3, early.tileLog(0));
  for (SelectionLearner* l : {&guideLike, &bsdfLike, &early}) l->update();
  // A 10-degree cone against the cosine lobe: the guide-heavy mixture's moment is a small share of
  // the BSDF's.
  EXPECT_GT(guideLike.guideGain(), 0.0);
  EXPECT_LT(guideLike.guideGain(), 0.2);
  EXPECT_DOUBLE_EQ(bsdfLike.guideGain(), 1.0);
  EXPECT_EQ(early.guideGain(), -1.0);
}

// Two kinds of sample, drawn with density 1: P where the BSDF's density is twice the guide's, Q the
// other way round. Their second moment under candidate a is then exactly
// nP / (0.5 + 0.5 a) + nQ / (1 - 0.5 a).
float learnedFrom(int nP, int nQ) {
  SelectionLearner learner(1, 1, 0.5f);
  for (int i = 0; i < nP; ++i) learner.tileLog(0).add(0, 1.0f, 0.5f, 1.0f, 1.0f);
  for (int i = 0; i < nQ; ++i) learner.tileLog(0).add(0, 0.5f, 1.0f, 1.0f, 1.0f);
  learner.update();
  return learner.bsdfProbability(0);
}

TEST(SelectionLearner, TakesTheMostBsdfWithinTheMarginOfTheLeastMoment) {
  ASSERT_NEAR(SelectionLearner::kStratifiedMargin, 0.1, 1e-12) << "the cases below are worked out for 10 %";
  ASSERT_NEAR(SelectionLearner::kBsdfOnlyMargin, 0.25, 1e-12) << "and for 25 % for the BSDF alone";
  // Moments over the candidates 0.1, 0.3, 0.5, 0.75, 1, above the least:
  // nQ = nP / 2: 21 %, 9.5 %, 2.9 %, 0, 2.9 %: 1 within the margin.
  EXPECT_EQ(learnedFrom(64, 32), 1.0f);
  // nQ = 5 nP: 0, 4.8 %, 13 %, 29 %, 55 %: 0.3 is the most BSDF within 10 %, 1 is beyond 25 %.
  EXPECT_EQ(learnedFrom(13, 65), 0.3f);
  // nQ = 3 nP: 0, 1.8 %, 7.2 %, 19 %, 41 %: the most BSDF within the margin, not one step towards it.
  EXPECT_EQ(learnedFrom(8, 24), 0.5f);
  // nQ = 2 nP: 0.8 %, 0, 2.8 %, 12 %, 28.5 %: 0.5; the BSDF alone just beyond its margin.
  EXPECT_EQ(learnedFrom(32, 64), 0.5f);
}

TEST(SelectionLearner, TakesTheBsdfAloneWithinItsWiderMargin) {
  // A guide share splits the pixel's stratified points between two strategies, which the moments of
  // independent samples do not see: the BSDF alone wins within kBsdfOnlyMargin of the least.
  // nQ = nP: 7.7 %, 1.8 %, 0, 2.9 %, 12.5 %: 0.75 within 10 %, but 1 within 25 %.
  EXPECT_EQ(learnedFrom(64, 64), 1.0f);
  // nQ = 1.5 nP: 2.8 %, 0, 0.9 %, 7.3 %, 21 %.
  EXPECT_EQ(learnedFrom(32, 48), 1.0f);
}

TEST(SelectionLearner, TakesTheBsdfWherePathsBroughtNothingBack) {
  // Every moment is 0: nothing speaks for the guide, and the BSDF's samples are the stratified ones.
  SelectionLearner learner(1, 1, 0.5f);
  for (uint32_t i = 0; i < SelectionLearner::kMinSamples; ++i) learner.tileLog(0).add(0, 1.0f, 0.5f, 1.0f, 0.0f);
  learner.update();
  EXPECT_EQ(learner.bsdfProbability(0), 1.0f);
}

TEST(SelectionLearner, KeepsThePriorUntilACachePointHasEnoughSamples) {
  const Setting s;
  SelectionLearner learner(2, 1, 0.5f);
  logSamples(s, true, 0.5f, int(SelectionLearner::kMinSamples) - 1, 3, learner.tileLog(0));
  learner.update();
  EXPECT_EQ(learner.bsdfProbability(0), 0.5f);
  EXPECT_EQ(learner.bsdfProbability(1), 0.5f);
  EXPECT_LT(learner.meanLearnedProbability(), 0.0) << "no cache point has learned yet";
  logSamples(s, true, 0.5f, 1, 4, learner.tileLog(0));  // the 32nd: enough, counted across passes
  learner.update();
  EXPECT_EQ(learner.bsdfProbability(0), SelectionLearner::kCandidates.front());
  EXPECT_EQ(learner.bsdfProbability(1), 0.5f) << "a cache point without samples moved";
}

TEST(SelectionLearner, SkipsSamplesThatCarryNoInformation) {
  SelectionLearner learner(1, 1, 0.5f);
  for (int i = 0; i < 100; ++i) {
    learner.tileLog(0).add(0, 0.3f, 0.2f, 0.0f, 1.0f);        // a density of 0 was never drawn
    learner.tileLog(0).add(0, 0.3f, 0.2f, 0.25f, NAN);        // a non-finite estimate
    learner.tileLog(0).add(0, 0.3f, 0.2f, 0.25f, -1.0f);      // a negative one
  }
  learner.update();
  EXPECT_EQ(learner.bsdfProbability(0), 0.5f);
}

TEST(SelectionLearner, DoesNotDependOnHowSamplesAreSpreadOverTiles) {
  const Setting s;
  SelectionLearner oneTile(1, 4, 0.5f), fourTiles(1, 4, 0.5f);
  for (int t = 0; t < 4; ++t) {
    logSamples(s, t % 2 == 0, 0.5f, 500, 10 + uint64_t(t), oneTile.tileLog(0));
    logSamples(s, t % 2 == 0, 0.5f, 500, 10 + uint64_t(t), fourTiles.tileLog(uint32_t(3 - t)));
  }
  oneTile.update();
  fourTiles.update();
  EXPECT_EQ(oneTile.bsdfProbability(0), fourTiles.bsdfProbability(0));
}

}  // namespace
}  // namespace vpl
