// `--join-depth auto`'s decision (render/session/join_depth_trial.h): the candidate of least variance
// x rays wins, a single bright sample does not decide, and the pixels are weighed by the image before
// the trial. That every depth, and so every mix of them, keeps the image unbiased is checked pixel
// by pixel against brdf (test_guided_modes, cornell_box_mis_join_depth_auto) and by the furnace; that
// the tracer's counterfactual estimate is depth 1's own, in test_path_tracer.
#include <functional>
#include <utility>
#include <gtest/gtest.h>
#include "render/film/film.h"
#include "render/integrator/light_vertex_cache.h"
#include "render/sampling/rng.h"
#include "render/session/join_depth_trial.h"
#include "render/session/tile_renderer.h"

namespace vpl {
namespace {

constexpr int kSize = 36;

// Runs a whole trial: the image so far is `mean` everywhere, and each trial pass draws every pixel of
// candidate c's film from sample(c, rng), which traces rays[c].
JoinDepthTrial runTrial(float mean, const std::function<float(size_t, Rng&)>& sample,
                        const std::array<double, JoinDepthTrial::kCandidates.size()>& rays, uint64_t seed = 1,
                        const std::function<void(uint64_t, int, int, Film&)>& alter = {}) {
  JoinDepthTrial trial(kSize, kSize);
  Film before(kSize, kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) before.addSample(x, y, glm::vec3(mean));
  trial.start(before);
  Rng rng(seed);
  std::array<Film, JoinDepthTrial::kCandidates.size()> films{Film(kSize, kSize), Film(kSize, kSize)};
  for (uint64_t p = JoinDepthTrial::kFirstPass; p <= JoinDepthTrial::kLastPass; ++p) {
    EXPECT_TRUE(JoinDepthTrial::isTrialPass(p));
    EXPECT_FALSE(trial.decided());
    EXPECT_EQ(trial.depthFor(p), -1);  // the trial's passes join at every vertex
    for (size_t c = 0; c < films.size(); ++c) {
      films[c].clear();
      for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) films[c].addSample(x, y, glm::vec3(sample(c, rng)));
      if (alter) alter(p, JoinDepthTrial::kCandidates[c], kSize, films[c]);
    }
    trial.record(p, {&films[0], &films[1]}, rays);
  }
  EXPECT_TRUE(trial.decided());
  return trial;
}

// Records every trial pass, each pixel of pass p drawing (every vertex's, depth 1's) from samples(x, p).
void recordPasses(JoinDepthTrial& trial, const std::function<std::pair<glm::vec3, glm::vec3>(int, uint64_t)>& samples) {
  Film every(kSize, kSize), one(kSize, kSize);
  for (uint64_t p = JoinDepthTrial::kFirstPass; p <= JoinDepthTrial::kLastPass; ++p) {
    every.clear();
    one.clear();
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        const auto [a, b] = samples(x, p);
        every.addSample(x, y, a);
        one.addSample(x, y, b);
      }
    trial.record(p, {&every, &one}, {1.0, 1.0});
  }
}

// Candidate c's samples: uniform around 1 with half-width spread[c].
std::function<float(size_t, Rng&)> uniformAround1(std::array<float, 2> spread) {
  return [spread](size_t c, Rng& rng) { return 1.0f + spread[c] * (2.0f * rng.uniform() - 1.0f); };
}

TEST(JoinDepthTrial, MeasuresBothCandidatesThenKeepsTheWinner) {
  JoinDepthTrial trial(4, 4);
  EXPECT_EQ(trial.depthFor(0), -1);  // every vertex before the trial
  EXPECT_FALSE(JoinDepthTrial::isTrialPass(JoinDepthTrial::kFirstPass - 1));
  EXPECT_FALSE(JoinDepthTrial::isTrialPass(JoinDepthTrial::kLastPass + 1));

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
  // Between equal variances, rays decide, but depth 1 must forecast a clear gain (kForecastMargin):
  // 0.8x every vertex's rays win, 0.95x do not.
  static_assert(JoinDepthTrial::kForecastMargin > 0.85 && JoinDepthTrial::kForecastMargin < 0.92);
  EXPECT_EQ(runTrial(1.0f, uniformAround1({0.3f, 0.3f}), {1.0, 0.8}).chosen(), 1);
  EXPECT_EQ(runTrial(1.0f, uniformAround1({0.3f, 0.3f}), {1.0, 0.95}).chosen(), -1);
  EXPECT_EQ(runTrial(1.0f, uniformAround1({0.3f, 0.3f}), {0.9, 1.0}).chosen(), -1);
}

// A rare bright sample in one pixel of the best candidate's pass (a Cornell box's trial had one that
// tripled a candidate's variance sum) does not hand the render to a worse candidate.
TEST(JoinDepthTrial, OneBrightSampleDoesNotDecide) {
  // Every vertex's film of the first trial pass, with one pixel's sample replaced by 400.
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

// Each channel counts as much as relMSE counts it, not by its share of luminance: depth 1's noise only
// in blue (7 % of luminance), with twice the spread of every vertex's grey noise, is the worse of the two.
TEST(JoinDepthTrial, CountsEveryChannelAsRelMseDoes) {
  JoinDepthTrial trial(kSize, kSize);
  Film before(kSize, kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) before.addSample(x, y, glm::vec3(1.0f));
  trial.start(before);
  Rng rng(3);
  recordPasses(trial, [&](int, uint64_t) {
    const glm::vec3 every(1.0f + 0.2f * (2.0f * rng.uniform() - 1.0f));
    return std::pair{every, glm::vec3(1.0f, 1.0f, 1.0f + 0.4f * (2.0f * rng.uniform() - 1.0f))};
  });
  EXPECT_EQ(trial.chosen(), -1);
  EXPECT_NEAR(trial.scores()[1] / trial.scores()[0], 4.0 / 3.0, 0.25);
}

// Without the image before it, the trial keeps every vertex rather than guess, though depth 1's passes
// (all alike) have no variance and every vertex's do.
TEST(JoinDepthTrial, KeepsEveryVertexWithoutAStart) {
  JoinDepthTrial trial(kSize, kSize);
  recordPasses(trial, [](int x, uint64_t p) { return std::pair{glm::vec3(float(x % 3) + float(p)), glm::vec3(float(x % 3))}; });
  EXPECT_TRUE(trial.decided());
  EXPECT_EQ(trial.chosen(), -1);
}

// The render loops' side (render_job, progressive_session): every pass joins to the depth of its
// slot (every vertex until the decision), trial passes render into a film of their own whose samples
// reach the image at full weight and into the counterfactual's, which never does, and the last complete
// trial pass decides from the rays each candidate traced or would have. As in the viewer, the first
// trial pass is cut short (a mode switch) and run again: its samples count in the image, but neither
// its rays nor its variance nor the pixel weights (set when the pass before the trial completes) may see them.
TEST(JoinDepthTrial, PassesRouteTrialSamplesToTheirOwnFilmsAndIntoTheImage) {
  static_assert(JoinDepthTrial::kFirstPass == 4 && JoinDepthTrial::kLastPass == 7);
  JoinDepthTrial trial(2, 1);
  LightVertexCache joins{ConnectionSettings{}};
  Film image(2, 1);
  double sum = 0.0;
  int samples = 0;
  const auto runPass = [&](uint64_t slot, float value, float counterfactual, bool complete, uint64_t rays, uint64_t past) {
    joins.setJoinDepth(7);
    const JoinDepthTrial::PassTargets target = trial.beginPass(slot, image, joins);
    EXPECT_EQ(joins.joinDepth(), trial.depthFor(slot)) << slot;
    EXPECT_EQ(joins.joinDepth(), slot <= JoinDepthTrial::kLastPass ? -1 : 1) << slot;
    EXPECT_EQ(&target.film == &image, !JoinDepthTrial::isTrialPass(slot)) << slot;
    EXPECT_EQ(target.counterfactual != nullptr, JoinDepthTrial::isTrialPass(slot)) << slot;
    for (int x = 0; x < 2; ++x) {
      target.film.addSample(x, 0, glm::vec3(value));
      if (target.counterfactual) {
        EXPECT_EQ(target.counterfactualDepth, 1);
        target.counterfactual->addSample(x, 0, glm::vec3(counterfactual));
      }
    }
    PassStats stats;
    stats.rays = rays;
    stats.raysPastCounterfactual = past;
    trial.endPass(slot, image, complete, stats, joins);  // joins never built: no light-path rays
    sum += value, ++samples;
    EXPECT_NEAR(image.resolve().pixels[0].x, sum / samples, 1e-4) << slot;
    EXPECT_EQ(trial.decided(), slot >= JoinDepthTrial::kLastPass) << slot;
  };
  for (uint64_t slot = 0; slot < JoinDepthTrial::kFirstPass; ++slot) runPass(slot, float(slot + 1), 0.0f, true, 4, 0);
  runPass(4, 1000.0f, 1000.0f, false, 400, 0);  // cut short
  // Every vertex draws 1, 5, 1, 5 in 4 rays a pass, depth 1 2, 3, 2, 3 in 4 - 1.
  for (uint64_t slot = JoinDepthTrial::kFirstPass; slot <= JoinDepthTrial::kLastPass + 1; ++slot) {
    const bool odd = slot % 2 == 1;
    runPass(slot, slot <= JoinDepthTrial::kLastPass ? (odd ? 5.0f : 1.0f) : 4.0f, odd ? 3.0f : 2.0f, true, 4, 1);
  }
  EXPECT_EQ(trial.chosen(), 1);
  EXPECT_EQ(joins.joinDepth(), 1);
  // Variances 16 / 3 and 1 / 3, weight 1 / (2.5^2 + 0.01) from the mean of the passes 1 ... 4.
  EXPECT_NEAR(trial.scores()[0], 16.0 / 3.0 / 6.26 * 4.0, 1e-5);
  EXPECT_NEAR(trial.scores()[1], 1.0 / 3.0 / 6.26 * 3.0, 1e-5);
}

}  // namespace
}  // namespace vpl
