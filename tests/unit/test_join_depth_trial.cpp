// `--join-depth auto`'s decision (render/session/join_depth_trial.h): the candidate of least variance
// x rays wins, a single bright sample does not decide, and the pixels are weighed by the image before
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
// draws every pixel from sample(c, rng), tracing rays[c].
JoinDepthTrial runTrial(float mean, const std::function<float(size_t, Rng&)>& sample,
                        const std::array<double, JoinDepthTrial::kCandidates.size()>& rays, uint64_t seed = 1,
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
    trial.record(p, pass, rays[c]);
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
  // The scores: the variance of a uniform of half-width w is w^2 / 3, over (1 + 0.01) times rays.
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
// trial passes render into a film of their own whose samples still reach the image, weighing half as
// much as the others', and the last complete trial pass decides. As in the viewer, the first trial
// pass is cut short (a mode switch) and run again: its samples count in the image, but neither its
// rays nor its variance nor the pixel weights (set when the pass before the trial completes) may see them.
TEST(JoinDepthTrial, PassesRouteTrialSamplesToTheirOwnFilmAndIntoTheImage) {
  static_assert(JoinDepthTrial::kFirstPass == 4 && JoinDepthTrial::kLastPass == 7);
  JoinDepthTrial trial(2, 1);
  LightVertexCache joins{ConnectionSettings{}};
  Film image(2, 1);
  double sum = 0.0, weights = 0.0;
  const auto runPass = [&](uint64_t slot, float value, bool complete, double rays) {
    joins.setJoinDepth(7);
    Film& target = trial.beginPass(slot, image, joins);
    EXPECT_EQ(joins.joinDepth(), trial.depthFor(slot)) << slot;
    EXPECT_EQ(&target == &image, !JoinDepthTrial::isTrialPass(slot)) << slot;
    target.addSample(0, 0, glm::vec3(value));
    target.addSample(1, 0, glm::vec3(value));
    trial.endPass(slot, image, complete, rays, joins);  // joins never built: no light-path rays
    const double weight = JoinDepthTrial::isTrialPass(slot) ? 0.5 : 1.0;
    sum += weight * value, weights += weight;
    EXPECT_NEAR(image.resolve().pixels[0].x, sum / weights, 1e-4) << slot;
    EXPECT_EQ(trial.decided(), slot >= JoinDepthTrial::kLastPass) << slot;
  };
  for (uint64_t slot = 0; slot < JoinDepthTrial::kFirstPass; ++slot) runPass(slot, float(slot + 1), true, 0.5);
  runPass(4, 1000.0f, false, 100.0);  // cut short
  // Candidate -1 (slots 4 and 7) draws 1 and 5, candidate 1 (slots 5 and 6) 2 and 3.
  const float values[] = {1.0f, 2.0f, 3.0f, 5.0f};
  for (uint64_t slot = JoinDepthTrial::kFirstPass; slot <= JoinDepthTrial::kLastPass + 1; ++slot)
    runPass(slot, slot <= JoinDepthTrial::kLastPass ? values[slot - 4] : 4.0f, true, 0.5);
  EXPECT_EQ(trial.chosen(), 1);
  EXPECT_EQ(joins.joinDepth(), 1);
  // Variance (5 - 1)^2 / 2 = 8, weight 1 / (2.5^2 + 0.01) from the mean of the passes 1 ... 4, 0.5 rays per pass.
  EXPECT_NEAR(trial.scores()[0], 8.0 / 6.26 * 0.5, 1e-6);
  EXPECT_NEAR(trial.scores()[1], 0.5 / 6.26 * 0.5, 1e-6);
}

}  // namespace
}  // namespace vpl
