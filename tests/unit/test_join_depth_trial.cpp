// `--join-depth auto`'s decision (render/session/join_depth_trial.h): the candidate of least variance
// x time wins, a single bright sample does not decide, and the pixels are weighed by the image before
// the trial. That every depth, and so every mix of them, keeps the image unbiased is checked pixel
// by pixel against brdf (test_guided_modes, cornell_box_mis_join_depth_auto) and by the furnace.
#include <functional>
#include <gtest/gtest.h>
#include "render/film/film.h"
#include "render/integrator/light_vertex_cache.h"
#include "render/sampling/rng.h"
#include "render/session/join_depth_trial.h"

namespace vpl {
namespace {

constexpr int kSize = 36;

// Runs a whole trial: the image so far is `mean` everywhere, and each trial pass of candidate c
// draws every pixel from sample(c, rng), taking seconds[c].
JoinDepthTrial runTrial(float mean, const std::function<float(size_t, Rng&)>& sample,
                        const std::array<double, JoinDepthTrial::kCandidates.size()>& seconds, uint64_t seed = 1,
                        const std::function<void(uint64_t, int, int, Film&)>& alter = {}) {
  JoinDepthTrial trial(kSize, kSize);
  Film before(kSize, kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) before.addSample(x, y, glm::vec3(mean));
  trial.start(before);
  Rng rng(seed);
  Film pass(kSize, kSize);
  for (uint64_t p = JoinDepthTrial::kFirstPass; p <= JoinDepthTrial::kLastPass; ++p) {
    EXPECT_TRUE(JoinDepthTrial::isTrialPass(p));
    EXPECT_FALSE(trial.decided());
    size_t c = 0;
    while (JoinDepthTrial::kCandidates[c] != trial.depthFor(p)) ++c;
    pass.clear();
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) pass.addSample(x, y, glm::vec3(sample(c, rng)));
    if (alter) alter(p, trial.depthFor(p), kSize, pass);
    trial.record(p, pass, seconds[c]);
  }
  EXPECT_TRUE(trial.decided());
  return trial;
}

// Candidate c's samples: uniform around 1 with half-width spread[c].
std::function<float(size_t, Rng&)> uniformAround1(std::array<float, 2> spread) {
  return [spread](size_t c, Rng& rng) { return 1.0f + spread[c] * (2.0f * rng.uniform() - 1.0f); };
}

TEST(JoinDepthTrial, TriesEachCandidateInTurnThenKeepsTheWinner) {
  JoinDepthTrial trial(4, 4);
  EXPECT_EQ(trial.depthFor(0), -1);  // every vertex before the trial
  EXPECT_FALSE(JoinDepthTrial::isTrialPass(JoinDepthTrial::kFirstPass - 1));
  EXPECT_FALSE(JoinDepthTrial::isTrialPass(JoinDepthTrial::kLastPass + 1));
  for (size_t i = 0; i < JoinDepthTrial::kCandidates.size(); ++i)
    EXPECT_EQ(trial.depthFor(JoinDepthTrial::kFirstPass + i), JoinDepthTrial::kCandidates[i]);

  // Candidate 1 (depth 1) has a quarter of the variance at 1.5x the time: it wins; at 5x it loses.
  const JoinDepthTrial cheap = runTrial(1.0f, uniformAround1({0.4f, 0.2f}), {1.0, 1.5});
  EXPECT_EQ(cheap.chosen(), 1);
  EXPECT_EQ(cheap.depthFor(JoinDepthTrial::kLastPass + 1), 1);
  EXPECT_EQ(cheap.depthFor(1000), 1);
  // The scores: the variance of a uniform of half-width w is w^2 / 3, over (1 + 0.01) times seconds.
  EXPECT_NEAR(cheap.scores()[0], 0.16 / 3.0 / 1.01 * 1.0, 0.02);
  EXPECT_NEAR(cheap.scores()[1], 0.04 / 3.0 / 1.01 * 1.5, 0.006);
  const JoinDepthTrial dear = runTrial(1.0f, uniformAround1({0.4f, 0.2f}), {1.0, 5.0});
  EXPECT_EQ(dear.chosen(), -1);
  // Time alone decides between equal variances.
  EXPECT_EQ(runTrial(1.0f, uniformAround1({0.3f, 0.3f}), {1.0, 0.9}).chosen(), 1);
  EXPECT_EQ(runTrial(1.0f, uniformAround1({0.3f, 0.3f}), {0.9, 1.0}).chosen(), -1);
}

// A rare bright sample in one pixel of the best candidate's pass (a Cornell box's trial had one that
// tripled a candidate's variance sum) does not hand the render to a worse candidate.
TEST(JoinDepthTrial, OneBrightSampleDoesNotDecide) {
  // Every vertex's first trial pass, with one pixel's sample replaced by 400.
  const auto spike = [](uint64_t pass, int depth, int size, Film& film) {
    if (pass != JoinDepthTrial::kFirstPass || depth != -1) return;
    const Image image = film.resolve();
    film.clear();
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) film.addSample(x, y, x == size / 2 && y == size / 2 ? glm::vec3(400.0f) : image.at(x, y));
  };
  const auto samples = uniformAround1({0.2f, 0.3f});
  EXPECT_EQ(runTrial(1.0f, samples, {1.0, 1.0}).chosen(), -1);
  EXPECT_EQ(runTrial(1.0f, samples, {1.0, 1.0}, 1, spike).chosen(), -1);
}

// The pixels are weighed by the image before the trial, as relMSE weighs them by the reference:
// the same samples about a mean of 10 have a hundredth of the relative variance of those about 1,
// and a dark image (mean 0) weighs by 1 / 0.01.
TEST(JoinDepthTrial, WeighsPixelsByTheImageBeforeTheTrial) {
  const auto samples = uniformAround1({0.4f, 0.2f});
  const JoinDepthTrial bright = runTrial(10.0f, samples, {1.0, 1.5});
  EXPECT_NEAR(bright.scores()[0], 0.16 / 3.0 / 100.01, 2e-4);
  const JoinDepthTrial dark = runTrial(0.0f, samples, {1.0, 1.5});
  EXPECT_NEAR(dark.scores()[0], 0.16 / 3.0 / 0.01, 2.0);
}

// Without the image before it, the trial keeps every vertex rather than guess, though depth 1's passes
// (all alike) have no variance and every vertex's do.
TEST(JoinDepthTrial, KeepsEveryVertexWithoutAStart) {
  JoinDepthTrial trial(kSize, kSize);
  Film pass(kSize, kSize);
  for (uint64_t p = JoinDepthTrial::kFirstPass; p <= JoinDepthTrial::kLastPass; ++p) {
    pass.clear();
    const float shift = trial.depthFor(p) == -1 ? float(p) : 0.0f;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) pass.addSample(x, y, glm::vec3(float(x % 3) + shift));
    trial.record(p, pass, 1.0);
  }
  EXPECT_TRUE(trial.decided());
  EXPECT_EQ(trial.chosen(), -1);
}

// The render loops' side (render_job, progressive_session): each pass joins to the depth of its slot,
// trial passes render into a film of their own whose samples still reach the image, a pass cut short
// is not recorded, and the last complete trial pass decides.
TEST(JoinDepthTrial, PassesRouteTrialSamplesToTheirOwnFilmAndIntoTheImage) {
  JoinDepthTrial trial(2, 1);
  LightVertexCache joins{ConnectionSettings{}};
  Film image(2, 1);
  const auto fill = [](Film& f, float v) { f.addSample(0, 0, glm::vec3(v)), f.addSample(1, 0, glm::vec3(v)); };
  for (uint64_t slot = 0; slot <= JoinDepthTrial::kLastPass + 1; ++slot) {
    joins.setJoinDepth(7);
    Film& target = trial.beginPass(slot, image, joins);
    EXPECT_EQ(joins.joinDepth(), trial.depthFor(slot)) << slot;
    EXPECT_EQ(&target == &image, !JoinDepthTrial::isTrialPass(slot)) << slot;
    fill(target, float(slot + 1));
    // The first trial pass is cut short: its samples count in the image, its time and variance do not,
    // so the trial needs one more pass of that candidate than it gets and decides from the rest.
    trial.endPass(slot, image, slot != JoinDepthTrial::kFirstPass, 0.5);
    EXPECT_FLOAT_EQ(image.resolve().pixels[0].x, float(slot + 2) / 2.0f) << slot;  // the mean of 1 ... slot + 1
  }
  EXPECT_TRUE(trial.decided());
  EXPECT_EQ(joins.joinDepth(), trial.chosen());
}

}  // namespace
}  // namespace vpl
