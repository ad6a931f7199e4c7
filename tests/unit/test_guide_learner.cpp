// The learned guide (render/guide/guide_learner.h): the VPLs decide the first pass, the paths' records
// move the guide to where the light really comes from, and every learned table keeps an exact pdf.
#include <cmath>
#include <vector>
#include <gtest/gtest.h>
#include "render/guide/guide_learner.h"
#include "render/session/film_learners.h"
#include "render/sampling/rng.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

const glm::vec3 kPriorDirection(0, 0, 1);     // where the VPLs say the light is
const glm::vec3 kLightDirection(-1, 0, 0);    // where it really is
constexpr float kLightCos = 0.95f;            // a cone of 18 degrees around it

GuideSettings settings() { return GuideSettings{}; }

// Cache point 0 has a VPL prior towards +z, cache point 1 none (no cluster reached it).
GuideField field() {
  const GuideSettings s = settings();
  std::vector<CachePoint> points(2);
  points[0].distribution = GuideDistribution({{kPriorDirection, 1.0f, 0.0f}}, s.coneAngle, s.defensive);
  points[1].position = glm::vec3(10, 0, 0);
  points[1].distribution = GuideDistribution(std::vector<GuideRepresentative>{}, s.coneAngle, s.defensive);
  for (CachePoint& p : points) p.radius = 1.0f;
  return GuideField(points, s);
}

// What a first vertex brings back: light of radiance 1 in the cone around kLightDirection.
float incoming(const glm::vec3& w) { return glm::dot(w, kLightDirection) >= kLightCos ? 1.0f : 0.0f; }

// `passes` passes of `perPass` first vertices at cache point c, each drawn from the pass's guide
// and logged as F / q, spread over two tiles.
void learn(GuideLearner& learner, int c, int passes, int perPass, uint64_t seed) {
  Rng rng(seed);
  for (int pass = 0; pass < passes; ++pass) {
    for (int i = 0; i < perPass; ++i) {
      const GuideDistribution& d = learner.distribution(c);
      const glm::vec3 w = d.sample(rng);
      learner.tileLog(uint32_t(i % 2)).add(c, w, incoming(w) / d.pdf(w));
    }
    learner.update();
  }
}

double integral(const GuideDistribution& d) {
  double sum = 0.0;
  for (int cell = 0; cell < GuideDistribution::kCells; ++cell)
    sum += double(d.pdf(GuideDistribution::cellCentre(cell))) * GuideDistribution::kCellSolidAngle;
  return sum;
}

TEST(GuideLearner, ThePriorDecidesTheFirstPass) {
  const GuideField f = field();
  const GuideLearner withPrior(f, 2, true, settings().defensive), learnedOnly(f, 2, false, settings().defensive);
  for (const glm::vec3& w : {kPriorDirection, kLightDirection, glm::normalize(glm::vec3(1, 2, -3))}) {
    EXPECT_EQ(withPrior.distribution(0).pdf(w), f.point(0).distribution.pdf(w));
    EXPECT_NEAR(learnedOnly.distribution(0).pdf(w), 1.0 / (4.0 * M_PI), 1e-6);
  }
}

TEST(GuideLearner, MovesTheGuideToWhereTheLightComesFrom) {
  const GuideField f = field();
  for (const bool prior : {true, false}) {
    GuideLearner learner(f, 2, prior, settings().defensive);
    const double before = learner.distribution(0).pdf(kLightDirection);
    learn(learner, 0, 32, 1024, 3);
    const GuideDistribution& d = learner.distribution(0);
    // 32768 samples against the prior's 512: the light's cells hold nearly all of the table, and the
    // prior's narrow cone, once 98 % of it, keeps under 2 %.
    const double lambda = prior ? 32768.0 / (32768.0 + GuideLearner::kPriorSamples) : 1.0;
    EXPECT_GT(d.pdf(kLightDirection), 20.0 * before) << (prior ? "vpl prior" : "no prior");
    EXPECT_GT(d.pdf(kLightDirection), 2.0 * d.pdf(kPriorDirection)) << (prior ? "vpl prior" : "no prior");
    double lightShare = 0.0;  // the table's mass in cells whose centres lie within 30 degrees of the light
    for (int cell = 0; cell < GuideDistribution::kCells; ++cell)
      if (glm::dot(GuideDistribution::cellCentre(cell), kLightDirection) > std::cos(0.52f)) lightShare += d.cellShare(cell);
    EXPECT_GT(lightShare, 0.9 * lambda) << (prior ? "vpl prior" : "no prior");
    EXPECT_NEAR(learner.meanLearnedShare(), 0.5 * lambda, 1e-9);
  }
}

TEST(GuideLearner, KeepsThePriorWhereNothingWasFound) {
  const GuideField f = field();
  GuideLearner learner(f, 1, true, settings().defensive);
  for (int i = 0; i < 100; ++i) learner.tileLog(0).add(0, kPriorDirection, 0.0f);
  learner.tileLog(0).add(0, kPriorDirection, NAN);  // counts as nothing found
  learner.update();
  EXPECT_EQ(learner.distribution(0).pdf(kPriorDirection), f.point(0).distribution.pdf(kPriorDirection));
}

// Learned tables are sampled exactly by both samplers and integrate to 1, with and without a prior,
// at the cache point whose prior was empty, and at both defensive shares (the guide-only modes', mis's).
TEST(GuideLearner, LearnedPdfStaysExact) {
  const GuideField f = field();
  for (const float defensive : {settings().defensive, settings().misDefensive})
  for (const bool prior : {true, false}) {
    GuideLearner learner(f, 2, prior, defensive);
    for (int c : {0, 1}) {
      learn(learner, c, 3, 128, 5 + uint64_t(c));  // few samples: prior and learned cells both weigh
      const GuideDistribution& d = learner.distribution(c);
      const std::string name = std::string(prior ? "vpl prior" : "no prior") + ", cache point " + std::to_string(c) +
                               ", defensive " + std::to_string(defensive);
      ASSERT_FALSE(d.uniform()) << name << ": nothing was learned";
      EXPECT_EQ(d.defensive(), defensive) << name;
      EXPECT_NEAR(integral(d), 1.0, 1e-4) << name;
      Rng rng(11);
      const auto pdf = [&](const glm::vec3& w) { return double(d.pdf(w)); };
      const auto one = test::chiSquareEqualArea([&] { return d.sample(rng); }, pdf, 200000, 2 * GuideDistribution::kResolution);
      EXPECT_GT(one.pValue, 1e-4) << name << ": " << one.report;
      const auto two = test::chiSquareEqualArea([&] { return d.sample(rng.uniform2()); }, pdf, 200000,
                                                2 * GuideDistribution::kResolution);
      EXPECT_GT(two.pValue, 1e-4) << name << ": " << two.report;
    }
  }
}

// mis's learned guides take mis's defensive share wherever its BSDF probability cannot fall below the
// learned one's least candidate; the guide-only modes, and mis where the guide alone may draw
// a direction, keep the heavier one.
TEST(GuideLearner, MisLearnsWithItsOwnDefensiveShareWhereTheBsdfStaysInTheMixture) {
  GuideSettings s = settings();
  ASSERT_LT(s.misDefensive, s.defensive);
  EXPECT_EQ(FilmLearners::learnedDefensive(SamplingMode::Mis, s), s.misDefensive);  // learned, from 0.5
  for (const SamplingMode guideOnly : {SamplingMode::Mixture, SamplingMode::Metropolis})
    EXPECT_EQ(FilmLearners::learnedDefensive(guideOnly, s), s.defensive);
  s.bsdfProbability = 0.05f;  // the learned probability starts below the share
  EXPECT_EQ(FilmLearners::learnedDefensive(SamplingMode::Mis, s), s.defensive);
  s.learnSelection = false;
  EXPECT_EQ(FilmLearners::learnedDefensive(SamplingMode::Mis, s), s.defensive);  // fixed at 0.05
  s.bsdfProbability = 0.5f;  // the paper's fixed probability
  EXPECT_EQ(FilmLearners::learnedDefensive(SamplingMode::Mis, s), s.misDefensive);

  // And the film's learned tables carry it.
  const GuideField f = field();
  FilmLearners film(f, SamplingMode::Mis, settings(), 1);
  GuideLearners logs = film.logs();
  ASSERT_NE(logs.directions, nullptr);
  for (int i = 0; i < 64; ++i) logs.directions->tileLog(0).add(0, kLightDirection, 1.0f);
  film.update();
  EXPECT_EQ(logs.directions->distribution(0).defensive(), settings().misDefensive);
  FilmLearners mixture(f, SamplingMode::Mixture, settings(), 1);
  for (int i = 0; i < 64; ++i) mixture.logs().directions->tileLog(0).add(0, kLightDirection, 1.0f);
  mixture.update();
  EXPECT_EQ(mixture.logs().directions->distribution(0).defensive(), settings().defensive);
}

}  // namespace
}  // namespace vpl
