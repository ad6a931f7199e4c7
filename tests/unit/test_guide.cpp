// The guide distribution, its Metropolis chain and the cache-point lookup, against their definitions.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <numbers>
#include <string>
#include <vector>
#include "render/guide/guide_distribution.h"
#include "render/guide/guide_field.h"
#include "render/guide/metropolis_sampler.h"
#include "render/sampling/equal_area_map.h"
#include "render/sampling/pixel_sampler.h"
#include "render/sampling/warps.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

constexpr float kDeg = std::numbers::pi_v<float> / 180.0f;

std::vector<GuideRepresentative> randomReps(size_t n, uint64_t seed, bool clustered = false) {
  Rng rng(seed);
  std::vector<GuideRepresentative> reps(n);
  const glm::vec3 axis = glm::normalize(glm::vec3(0.3f, 0.8f, 0.2f));
  for (auto& r : reps) {
    r.direction = clustered ? glm::normalize(axis + 0.3f * sampleUniformSphere(rng.uniform2())) : sampleUniformSphere(rng.uniform2());
    r.weight = 0.1f + 2.0f * rng.uniform();
  }
  return reps;
}

struct Case {
  const char* name;
  size_t reps;
  float coneDegrees;
  bool clustered;
  float widestRepDegrees = 0.0f;  // > 0: each representative asks for its own cone up to this wide
};

std::vector<Case> cases() {
  return {{"one wide", 1, 30, false},  {"one narrow", 1, 3, false},    {"few wide", 5, 30, true},
          {"few narrow", 5, 3, true},  {"many wide", 500, 30, false},  {"many narrow", 500, 3, true},
          {"near clusters", 20, 3, true, 90.0f}};
}

GuideDistribution makeDistribution(const Case& c, uint64_t seed, bool bilinear = true) {
  std::vector<GuideRepresentative> reps = randomReps(c.reps, seed, c.clustered);
  Rng rng(seed ^ 0xc0e5ull);
  for (GuideRepresentative& r : reps) r.coneAngle = rng.uniform() * c.widestRepDegrees * kDeg;
  return GuideDistribution(reps, c.coneDegrees * kDeg, 0.01f, bilinear);
}

// Every case in both forms of the density: constant over each cell, and bilinear between corners.
struct Form {
  const Case& c;
  bool bilinear;
  std::string name() const { return std::string(c.name) + (bilinear ? ", bilinear" : ", box"); }
};
template <class Test>
void forEachForm(Test&& test) {
  for (const Case& c : cases())
    for (bool bilinear : {false, true}) test(Form{c, bilinear});
}

TEST(GuideDistribution, PdfIntegratesToOneAndMatchesTheTarget) {
  forEachForm([](const Form& form) {
    const Case& c = form.c;
    const GuideDistribution d = makeDistribution(c, 1, form.bilinear);
    const double integral = test::integrateSphere([&](const glm::vec3& w) { return double(d.pdf(w)); }, 1024, 2048);
    EXPECT_NEAR(integral, 1.0, c.coneDegrees < 10 ? 0.03 : 0.005) << form.name();
    Rng rng(2);
    for (int i = 0; i < 200; ++i) {
      const glm::vec3 w = sampleUniformSphere(rng.uniform2());
      const double expected = 0.99 * d.target(w) / d.totalWeight() + 0.01 / (4.0 * std::numbers::pi);
      ASSERT_NEAR(d.pdf(w), expected, 1e-5 * expected) << form.name();
    }
  });
}

TEST(GuideDistribution, TargetIntegratesToTotalWeight) {
  for (bool bilinear : {false, true}) {
    const GuideDistribution d(randomReps(20, 3, true), 20.0f * kDeg, 0.01f, bilinear);
    const double integral = test::integrateSphere([&](const glm::vec3& w) { return double(d.target(w)); }, 1024, 2048);
    EXPECT_NEAR(integral, d.totalWeight(), 0.005 * d.totalWeight()) << bilinear;
  }
}

// The bilinear density is continuous across the edges between cells (within the square: its own
// edges fold onto each other), where the box density jumps. Two points 2e-4 of the square's side
// apart differ by at most 2e-4 x 32 = 0.64 % of the largest corner value when it is continuous.
TEST(GuideDistribution, BilinearDensityIsContinuousAcrossCellEdges) {
  const GuideDistribution smooth = makeDistribution(cases()[2], 4, true), box = makeDistribution(cases()[2], 4, false);
  constexpr int r = GuideDistribution::kResolution;
  constexpr float kStep = 1e-4f;
  Rng rng(8);
  double smoothJump = 0.0, boxJump = 0.0, smoothMax = 0.0, boxMax = 0.0;
  for (int i = 0; i < 20000; ++i) {
    // A point on a vertical edge between two cells, and one on either side of it.
    const float x = float(1 + int(rng.below(r - 1))) / float(r), y = 0.02f + 0.96f * rng.uniform();
    const glm::vec3 left = equalAreaSquareToSphere({x - kStep, y}), right = equalAreaSquareToSphere({x + kStep, y});
    smoothJump = std::max(smoothJump, double(std::abs(smooth.pdf(left) - smooth.pdf(right))));
    boxJump = std::max(boxJump, double(std::abs(box.pdf(left) - box.pdf(right))));
    smoothMax = std::max({smoothMax, double(smooth.pdf(left)), double(smooth.pdf(right))});
    boxMax = std::max({boxMax, double(box.pdf(left)), double(box.pdf(right))});
  }
  std::printf("largest jump of the pdf across a cell edge over its largest value: bilinear %.4f, box %.4f\n",
              smoothJump / smoothMax, boxJump / boxMax);
  EXPECT_LT(smoothJump, 0.0065 * smoothMax);
  EXPECT_GT(boxJump, 0.1 * boxMax) << "the test cannot see a jump";
}

TEST(GuideDistribution, KdTreeConeQueryEqualsLinearScan) {
  Rng rng(5);
  std::vector<uint32_t> tree, linear;
  for (float degrees : {1.0f, 3.0f, 10.0f, 20.4f, 45.0f, 120.0f, 180.0f}) {
    for (int i = 0; i < 500; ++i) {
      // A quarter of the queries right at cell centres, where the cone's edge passes through neighbours.
      const glm::vec3 w = i % 4 == 0 ? GuideDistribution::cellCentre(int(rng.below(GuideDistribution::kCells)))
                                     : sampleUniformSphere(rng.uniform2());
      tree.clear();
      linear.clear();
      GuideDistribution::coneCells(w, std::cos(degrees * kDeg), tree);
      GuideDistribution::coneCellsLinear(w, std::cos(degrees * kDeg), linear);
      std::sort(tree.begin(), tree.end());
      // The two may round a centre lying on the cone's edge differently; nothing else may differ.
      std::vector<uint32_t> differ;
      std::set_symmetric_difference(tree.begin(), tree.end(), linear.begin(), linear.end(), std::back_inserter(differ));
      for (uint32_t c : differ)
        ASSERT_NEAR(glm::dot(GuideDistribution::cellCentre(int(c)), w), std::cos(degrees * kDeg), 1e-5f) << degrees << " degrees";
      ASSERT_LE(differ.size(), 2u);
    }
  }
}

TEST(GuideDistribution, TargetIsTheConeAverageAtCellCentres) {
  // One representative: its weight spread over the cells whose centres see it within the cone.
  const glm::vec3 dir = glm::normalize(glm::vec3(0.2f, -0.5f, 0.7f));
  const GuideDistribution d({{dir, 3.0f}}, 20.0f * kDeg, 0.01f, false);
  std::vector<uint32_t> cells;
  GuideDistribution::coneCellsLinear(dir, std::cos(20.0f * kDeg), cells);
  ASSERT_GT(cells.size(), 10u);
  // The cone's cells hold the same solid angle as the cone, within the grid's resolution.
  const double coneSolidAngle = 2.0 * std::numbers::pi * (1.0 - std::cos(20.0 * kDeg));
  EXPECT_NEAR(double(cells.size()) * GuideDistribution::kCellSolidAngle, coneSolidAngle, 0.15 * coneSolidAngle);
  const double expected = 3.0 / (double(cells.size()) * GuideDistribution::kCellSolidAngle);
  for (uint32_t c : cells) ASSERT_NEAR(d.target(GuideDistribution::cellCentre(int(c))), expected, 1e-5 * expected);
  EXPECT_EQ(d.target(-dir), 0.0f);
  // A representative asking for a wider cone spreads the same weight over more cells.
  const GuideDistribution wide({{dir, 3.0f, 60.0f * kDeg}}, 20.0f * kDeg, 0.01f, false);
  cells.clear();
  GuideDistribution::coneCellsLinear(dir, std::cos(60.0f * kDeg), cells);
  const double wideExpected = 3.0 / (double(cells.size()) * GuideDistribution::kCellSolidAngle);
  for (uint32_t c : cells) ASSERT_NEAR(wide.target(GuideDistribution::cellCentre(int(c))), wideExpected, 1e-5 * wideExpected);
  EXPECT_NEAR(wide.totalWeight(), 3.0, 1e-6);
}

TEST(GuideDistribution, ZeroWeightIsUniform) {
  std::vector<GuideRepresentative> reps = {{glm::vec3(0, 0, 1), 0.0f}, {glm::vec3(1, 0, 0), -1.0f}};
  const GuideDistribution d(reps, 0.1f, 0.01f);
  EXPECT_FLOAT_EQ(d.pdf(glm::vec3(0, 0, 1)), uniformSpherePdf());
  const GuideDistribution empty({}, 0.1f, 0.01f);
  Rng rng(1);
  EXPECT_NEAR(glm::length(empty.sample(rng)), 1.0f, 1e-5f);
}

TEST(GuideDistribution, ExactSamplerMatchesPdf) {
  forEachForm([](const Form& form) {
    const GuideDistribution d = makeDistribution(form.c, 6, form.bilinear);
    Rng rng(7);
    const auto r = test::chiSquareEqualArea([&] { return d.sample(rng); }, [&](const glm::vec3& w) { return double(d.pdf(w)); },
                                            200000, 2 * GuideDistribution::kResolution);
    EXPECT_GT(r.pValue, 1e-4) << form.name() << ": " << r.report;
  });
}

// The one-number form that mis uses (the BSDF's 2D number, rescaled): same density.
TEST(GuideDistribution, SamplerFromOne2DNumberMatchesPdf) {
  forEachForm([](const Form& form) {
    const GuideDistribution d = makeDistribution(form.c, 6, form.bilinear);
    Rng rng(17);
    const auto r = test::chiSquareEqualArea([&] { return d.sample(rng.uniform2()); },
                                            [&](const glm::vec3& w) { return double(d.pdf(w)); }, 200000,
                                            2 * GuideDistribution::kResolution);
    EXPECT_GT(r.pValue, 1e-4) << form.name() << ": " << r.report;
  });
}

// ... and stratified numbers stay stratified: the count of directions above the equator from a
// 16x16 grid of jittered numbers strays from its expectation (the pdf's mass there) far less than
// from 256 independent numbers.
TEST(GuideDistribution, StratifiedNumbersGiveStratifiedDirections) {
  const GuideDistribution d = makeDistribution(cases()[2], 6);
  const double expected =
      256.0 * test::integrateSphere([&](const glm::vec3& w) { return w.z > 0.0f ? double(d.pdf(w)) : 0.0; }, 512, 1024);
  Rng rng(23);
  double stratified = 0.0, independent = 0.0;  // mean squared deviations over trials
  constexpr int kTrials = 200;
  for (int trial = 0; trial < kTrials; ++trial) {
    int s = 0, i = 0;
    for (int a = 0; a < 16; ++a)
      for (int b = 0; b < 16; ++b) {
        s += d.sample(glm::vec2((float(a) + rng.uniform()) / 16.0f, (float(b) + rng.uniform()) / 16.0f)).z > 0.0f;
        i += d.sample(rng.uniform2()).z > 0.0f;
      }
    stratified += (s - expected) * (s - expected) / kTrials;
    independent += (i - expected) * (i - expected) / kTrials;
  }
  std::printf("above the equator: expected %.1f, rms deviation %.2f stratified, %.2f independent\n", expected,
              std::sqrt(stratified), std::sqrt(independent));
  EXPECT_LT(stratified, 0.25 * independent) << "stratified numbers lost their stratification";
}

TEST(Metropolis, IndependentChainsAreDistributedByThePdf) {
  // Chains started exactly and run K mutations: their final states are independent draws of the
  // stationary density, which must be the pdf.
  GuideSettings settings;
  for (const Case& c : cases()) {
    const GuideDistribution d = makeDistribution(c, 8);
    Rng rng(9);
    ChainStats stats;
    auto sample = [&] {
      MetropolisChain chain(d, rng);
      glm::vec3 w;
      for (int k = 0; k < 5; ++k) w = chain.next(d, settings, rng, stats);
      return w;
    };
    const auto r = test::chiSquareEqualArea(sample, [&](const glm::vec3& w) { return double(d.pdf(w)); }, 100000,
                                            GuideDistribution::kResolution);
    EXPECT_GT(r.pValue, 1e-4) << c.name << ": " << r.report;
    const double acceptance = double(stats.accepted) / double(stats.proposals);
    EXPECT_GT(acceptance, 0.005) << c.name;
    EXPECT_LT(acceptance, 1.0) << c.name;
    std::printf("%-12s acceptance %.3f\n", c.name, acceptance);
  }
}

// Four bins of the sphere (split by the cosine with an axis near the representatives') with their
// pdf masses, and a check of correlated states' bin frequencies against them: each batch one row of
// frequencies, its error from the batches' spread (batch means).
struct CosineBins {
  explicit CosineBins(const GuideDistribution& d, const glm::vec3& binAxis = glm::vec3(0.3f, 0.8f, 0.2f))
      : axis(glm::normalize(binAxis)) {
    const double total = test::integrateSphere([&](const glm::vec3& w) { return double(d.pdf(w)); }, 512, 1024);
    for (int b = 0; b < 4; ++b)
      mass[b] = test::integrateSphere([&](const glm::vec3& w) { return bin(w) == b ? double(d.pdf(w)) : 0.0; }, 512, 1024) / total;
  }
  int bin(const glm::vec3& w) const { return std::clamp(int((glm::dot(w, axis) + 1.0f) * 2.0f), 0, 3); }
  void expectBatchMeansNearMasses(const std::vector<std::array<double, 4>>& freq) const {
    const double batches = double(freq.size());
    for (int k = 0; k < 4; ++k) {
      double mean = 0, var = 0;
      for (const auto& f : freq) mean += f[size_t(k)] / batches;
      for (const auto& f : freq) var += (f[size_t(k)] - mean) * (f[size_t(k)] - mean) / (batches - 1);
      EXPECT_NEAR(mean, mass[k], 5.0 * std::sqrt(var / batches) + 1e-4) << "bin " << k;
    }
  }
  glm::vec3 axis;
  double mass[4] = {};
};

TEST(Metropolis, LongChainVisitsBinsInProportion) {
  // One long chain (correlated states): bin frequencies against pdf mass, with batch-means errors.
  const GuideDistribution d(randomReps(5, 10, true), 30.0f * kDeg, 0.01f);
  GuideSettings settings;
  Rng rng(11);
  MetropolisChain chain(d, rng);
  ChainStats stats;
  const CosineBins bins(d);
  const int batches = 50, perBatch = 20000;
  std::vector<std::array<double, 4>> freq(batches);
  for (int b = 0; b < batches; ++b) {
    std::array<double, 4> f{};
    for (int i = 0; i < perBatch; ++i) f[size_t(bins.bin(chain.next(d, settings, rng, stats)))] += 1.0 / perBatch;
    freq[size_t(b)] = f;
  }
  bins.expectBatchMeansNearMasses(freq);
}

TEST(Metropolis, ChainsProposingFromPixelsStratifiedPairsKeepThePdf) {
  // As the renderer runs them: a chain per tile and pass, started at an exact sample, whose step for
  // each pixel of the tile proposes from that pixel's stratified pair of the pass (the BSDF
  // direction's slot). Bin frequencies against pdf mass, batch means over the chains.
  const GuideDistribution d(randomReps(5, 10, true), 30.0f * kDeg, 0.01f);
  GuideSettings settings;
  Rng rng(12);
  ChainStats stats;
  // Bins along the representatives' axis, and along z, which the uniform proposal's first number sets
  // (a step that let that number decide its acceptance too would lean towards +z).
  const CosineBins bins[2] = {CosineBins(d), CosineBins(d, glm::vec3(0.0f, 0.0f, 1.0f))};
  const int passes = 400, pixels = 256;
  std::vector<std::array<double, 4>> freq[2];
  for (int pass = 0; pass < passes; ++pass) {
    MetropolisChain chain(d, rng);
    std::array<double, 4> f[2]{};
    for (int p = 0; p < pixels; ++p) {
      PixelSampler sampler(5, uint64_t(p), uint64_t(pass));
      VertexSamples u(sampler, 0);
      const glm::vec2 point = u.bsdfDirection();
      const glm::vec3 w = chain.next(d, settings, rng, stats, &point);
      for (int b = 0; b < 2; ++b) f[b][size_t(bins[b].bin(w))] += 1.0 / pixels;
    }
    for (int b = 0; b < 2; ++b) freq[b].push_back(f[b]);
  }
  for (int b = 0; b < 2; ++b) bins[b].expectBatchMeansNearMasses(freq[b]);
}

TEST(Metropolis, ChainsFromABadStartForgetItAndFollowThePdf) {
  // From an exact start (the tests above) every state is already a draw of the pdf, so a chain that
  // keeps the pdf but cannot leave where it is (say, every independent proposal rejected: the 9-degree
  // perturbation alone) passes them. Here each chain starts where the pdf is lowest, or at the
  // centre of the lighter of two lobes, and runs 200 steps; its last state, one per chain, is
  // chi-square tested against the pdf. With the right rule the start is forgotten: in the slowest
  // case, the lobes, mass moves between them at about 4 % a step (uniform proposals landing in the
  // other lobe), so 200 steps leave e^-8 of the start.
  GuideSettings settings;
  const glm::vec3 axis = glm::normalize(glm::vec3(0.3f, 0.8f, 0.2f));
  struct BadStart {
    const char* name;
    GuideDistribution d;
    glm::vec3 start;
  };
  std::vector<BadStart> starts;
  {
    const GuideDistribution d(randomReps(5, 14, true), 30.0f * kDeg, 0.01f);
    int lowest = 0;
    for (int c = 1; c < GuideDistribution::kCells; ++c)
      if (d.pdf(GuideDistribution::cellCentre(c)) < d.pdf(GuideDistribution::cellCentre(lowest))) lowest = c;
    starts.push_back({"five clustered, from the lowest pdf", d, GuideDistribution::cellCentre(lowest)});
  }
  starts.push_back({"two lobes 1:4, from the lighter", GuideDistribution({{axis, 1.0f}, {-axis, 4.0f}}, 30.0f * kDeg, 0.01f), axis});
  for (const BadStart& b : starts) {
    Rng rng(15);
    ChainStats stats;
    auto sample = [&] {
      MetropolisChain chain(b.d, b.start);
      glm::vec3 w = b.start;
      for (int k = 0; k < 200; ++k) w = chain.next(b.d, settings, rng, stats);
      return w;
    };
    const auto r = test::chiSquareEqualArea(sample, [&](const glm::vec3& w) { return double(b.d.pdf(w)); }, 10000,
                                            GuideDistribution::kResolution / 2);
    EXPECT_GT(r.pValue, 1e-4) << b.name << ": " << r.report;
    std::printf("%s: p-value %.3g, acceptance %.3f\n", b.name, r.pValue, double(stats.accepted) / double(stats.proposals));
  }
}

TEST(Metropolis, SameSeedSameChain) {
  const GuideDistribution d(randomReps(50, 12), 10.0f * kDeg, 0.01f);
  GuideSettings settings;
  Rng a(3), b(3);
  MetropolisChain ca(d, a), cb(d, b);
  ChainStats s;
  for (int i = 0; i < 100; ++i) ASSERT_EQ(ca.next(d, settings, a, s), cb.next(d, settings, b, s));
}

TEST(GuideField, LookupIsTheNearestAgreeingCachePoint) {
  Rng rng(13);
  std::vector<CachePoint> points(300);
  for (size_t i = 0; i < points.size(); ++i) {
    CachePoint& p = points[i];
    p.position = glm::vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 10.0f;
    p.normal = i % 3 ? sampleUniformSphere(rng.uniform2()) : glm::vec3(0, 0, 1);
    // Mostly small, a few huge (the grid's list of large spheres), one degenerate.
    p.radius = i == 7 ? 0.0f : (i % 50 == 0 ? 8.0f : 0.2f + rng.uniform());
  }
  GuideSettings settings;
  const std::vector<CachePoint> copy = [&] {
    std::vector<CachePoint> c(points.size());
    for (size_t i = 0; i < c.size(); ++i) c[i] = {points[i].position, points[i].normal, points[i].radius, {}};
    return c;
  }();
  const GuideField field(std::move(points), settings);
  auto bruteForce = [&](const glm::vec3& p, const glm::vec3& n) {
    int best = -1;
    float bestDist2 = INFINITY;
    for (size_t i = 0; i < copy.size(); ++i) {
      const float r = copy[i].radius * settings.lookupRadiusScale;
      const float d2 = glm::dot(copy[i].position - p, copy[i].position - p);
      if (r > 0.0f && d2 <= r * r && glm::dot(copy[i].normal, n) >= settings.lookupCosNormal && d2 < bestDist2) {
        best = int(i);
        bestDist2 = d2;
      }
    }
    return best;
  };
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const glm::vec3 p = glm::vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 12.0f - 1.0f;
    const glm::vec3 n = i % 2 ? field.point(int(i % field.size())).normal : sampleUniformSphere(rng.uniform2());
    const int got = field.lookup(p, n);
    ASSERT_EQ(got, bruteForce(p, n)) << i;
    ASSERT_EQ(got, field.lookupLinear(p, n)) << i;
    hits += got >= 0;
  }
  EXPECT_GT(hits, 1000);
  // Far away, facing the other way, non-finite: no cache point.
  EXPECT_EQ(field.lookup(glm::vec3(100.0f), glm::vec3(0, 0, 1)), -1);
  EXPECT_EQ(field.lookup(field.point(1).position, -field.point(1).normal), -1);
  EXPECT_EQ(field.lookup(glm::vec3(NAN), glm::vec3(0, 0, 1)), -1);
  EXPECT_EQ(field.lookup(glm::vec3(1e30f), glm::vec3(0, 0, 1)), -1);
  EXPECT_EQ(GuideField().lookup(glm::vec3(0.0f), glm::vec3(0, 0, 1)), -1);
}

}  // namespace
}  // namespace vpl
