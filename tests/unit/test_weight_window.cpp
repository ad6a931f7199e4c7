// The VPL-driven roulette's two parts: the weight window's decisions, and the VPLs' irradiance
// estimate against a case with an analytic answer. That the rule keeps the path tracer unbiased is
// checked by the furnace (test_path_tracer) and pixel by pixel against the sqrt rule (test_guided_modes).
#include <cmath>
#include <gtest/gtest.h>
#include "render/film/film.h"
#include "render/integrator/path_tracer.h"
#include "render/integrator/weight_window.h"
#include "render/session/window_switch.h"
#include "render/sampling/rng.h"
#include "render/vpl/irradiance_grid.h"
#include "tests/unit/scene_builders.h"

namespace vpl {
namespace {

TEST(WeightWindow, RoulettesBelowSplitsAboveLeavesInside) {
  WeightWindowSettings s;  // width 5: the window is [1/3, 5/3]
  EXPECT_FLOAT_EQ(weightWindow(0.2f, s).survival, 0.2f);
  EXPECT_EQ(weightWindow(0.2f, s).split, 1);
  EXPECT_FLOAT_EQ(weightWindow(1.0f, s).survival, 1.0f);
  EXPECT_EQ(weightWindow(1.0f, s).split, 1);
  EXPECT_EQ(weightWindow(1.6f, s).split, 1);
  EXPECT_EQ(weightWindow(1.7f, s).split, 2);
  EXPECT_EQ(weightWindow(4.5f, s).split, 5);
  EXPECT_EQ(weightWindow(100.0f, s).split, s.maxSplit);
  // Never certain death: an estimate of zero may be wrong.
  EXPECT_FLOAT_EQ(weightWindow(0.0f, s).survival, WeightWindowSettings::kMinSurvival);
  // Undefined ratios change nothing.
  EXPECT_FLOAT_EQ(weightWindow(NAN, s).survival, 1.0f);
  EXPECT_EQ(weightWindow(NAN, s).split, 1);
  s.maxSplit = 1;
  EXPECT_EQ(weightWindow(100.0f, s).split, 1);
}

// Inside a closed box whose walls all emit le and reflect rho, radiance is le / (1 - rho) in every
// direction, so the irradiance on every wall is pi le / (1 - rho) (light paths are cut at 8
// bounces: rho^8 of it is missing). A cell's estimate is a count of VPLs (at least 16 expected),
// so single points scatter by a quarter or so; their mean must not be biased.
TEST(IrradianceGrid, MatchesTheFurnaceIrradiance) {
  for (const float rho : {0.0f, 0.5f}) {
    const float le = 0.5f;
    const RenderScene scene(test::furnaceScene(rho, le));
    const IrradianceGrid grid(scene, 1 << 18, 7, PathTracerSettings{}.maxDepth);
    const double expected = 3.14159265 * le * (1.0 - std::pow(rho, 8.0f)) / (1.0 - rho);
    Rng rng(3);
    double sum = 0.0;
    int far = 0;
    constexpr int kPoints = 1000;
    for (int i = 0; i < kPoints; ++i) {
      // A point on the floor (y = -1) seen from inside.
      const glm::vec3 p(2.0f * rng.uniform() - 1.0f, -1.0f, 2.0f * rng.uniform() - 1.0f);
      const double e = grid.irradiance(p, glm::vec3(0, 1, 0)).y;
      sum += e;
      if (e > 1.6 * expected || e < expected / 1.6) ++far;
      // The wall's other side, outside the box, receives nothing.
      EXPECT_EQ(grid.irradiance(p, glm::vec3(0, -1, 0)).y, 0.0f);
    }
    EXPECT_NEAR(sum / kPoints, expected, 0.03 * expected) << "rho " << rho;
    EXPECT_LT(far, kPoints / 20) << "rho " << rho << ": points off by more than 1.6x";
  }
}

TEST(IrradianceGrid, IsEmptyWithoutLight) {
  SkySettings noSky;
  noSky.explicitSky = true;
  noSky.radiance = glm::vec3(0.0f);
  const RenderScene scene(test::furnaceScene(0.5f, 0.0f), noSky);
  const IrradianceGrid grid(scene, 1 << 12, 1, PathTracerSettings{}.maxDepth);
  EXPECT_TRUE(grid.empty());
  EXPECT_EQ(grid.irradiance(glm::vec3(0, -1, 0), glm::vec3(0, 1, 0)), glm::vec3(0.0f));
}

// The auto rule's switch reads the film's relative variance per sample: samples that are mostly
// black with a rare bright one (light through a slit) turn it on, steady samples do not.
TEST(WindowSwitch, TurnsOnWhereSamplesVaryMoreThanTheirMean) {
  const auto filmOf = [](std::initializer_list<float> passes) {
    Film film(8, 8);
    for (const float v : passes)
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) film.addSample(x, y, glm::vec3(v));
    return film;
  };
  WindowSwitch steady;
  EXPECT_FALSE(steady.update(filmOf({1.0f, 1.5f, 1.0f, 1.5f})));
  EXPECT_NEAR(steady.relativeVariance(), (1.0 / 12.0) / (1.25 * 1.25), 1e-3);  // 0.0833 / 1.5625, n/(n-1)-corrected
  WindowSwitch rare;
  EXPECT_TRUE(rare.update(filmOf({8.0f, 0.0f, 0.0f, 0.0f})));
  EXPECT_NEAR(rare.relativeVariance(), 16.0 / 4.0, 1e-2);  // sample variance 16 around a mean of 2
  // Once on it stays on, whatever later passes say.
  EXPECT_TRUE(rare.update(filmOf({1.0f, 1.0f})));
  // Read after the first passes only: the statistic creeps up as rare samples arrive.
  EXPECT_FALSE(WindowSwitch::updateDue(1));
  EXPECT_TRUE(WindowSwitch::updateDue(2));
  EXPECT_FALSE(WindowSwitch::updateDue(3));
  EXPECT_TRUE(WindowSwitch::updateDue(4));
  EXPECT_FALSE(WindowSwitch::updateDue(8));
}

}  // namespace
}  // namespace vpl
