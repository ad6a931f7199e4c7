// Warps and the discrete distribution: every sampler against its own pdf (chi-square).
#include <cmath>
#include <numbers>
#include <vector>
#include "render/core/frame.h"
#include "render/sampling/distribution_1d.h"
#include "render/sampling/equal_area_map.h"
#include "render/sampling/fast_trig.h"
#include "render/sampling/rng.h"
#include "render/sampling/warps.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

constexpr double kSignificance = 1e-3;  // per test; the suite has a handful of them

TEST(Warps, UniformSphereMatchesPdf) {
  Rng rng(1);
  const auto r = test::chiSquareSphere([&] { return sampleUniformSphere(rng.uniform2()); },
                                       [](const glm::vec3&) { return double(uniformSpherePdf()); }, 200000);
  EXPECT_GT(r.pValue, kSignificance) << r.report;
}

TEST(Warps, UniformHemisphereMatchesPdf) {
  Rng rng(2);
  const auto r = test::chiSquareSphere([&] { return sampleUniformHemisphere(rng.uniform2()); },
                                       [](const glm::vec3& w) { return w.z > 0 ? double(uniformHemispherePdf()) : 0.0; }, 200000);
  EXPECT_GT(r.pValue, kSignificance) << r.report;
}

TEST(Warps, CosineHemisphereMatchesPdf) {
  Rng rng(3);
  const auto r = test::chiSquareSphere([&] { return sampleCosineHemisphere(rng.uniform2()); },
                                       [](const glm::vec3& w) { return double(cosineHemispherePdf(w.z)); }, 200000);
  EXPECT_GT(r.pValue, kSignificance) << r.report;
}

TEST(Warps, ConesMatchPdfAndIntegrateToOne) {
  for (float degrees : {60.0f, 20.0f}) {
    const Cone cone = Cone::fromAngle(degrees * kPi / 180.0f);
    const glm::vec3 axis = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
    const Frame frame = Frame::fromNormal(axis);
    Rng rng(4);
    auto pdf = [&](const glm::vec3& w) { return glm::dot(w, axis) >= cone.cosTheta() ? double(uniformConePdf(cone)) : 0.0; };
    const auto r = test::chiSquareSphere([&] { return frame.toWorld(sampleUniformCone(rng.uniform2(), cone)); }, pdf,
                                         200000, 64, 128, 48);
    EXPECT_GT(r.pValue, kSignificance) << degrees << " deg: " << r.report;
    EXPECT_NEAR(test::integrateSphere(pdf, 1024, 2048), 1.0, 0.02) << degrees;
  }
}

TEST(Warps, NarrowConeInvertsToUniformSquare) {
  // Narrow cones are too small for sphere bins: map the samples back to the unit square instead,
  // where a uniform cone is a uniform square (1 - cos theta linear in u.x, phi linear in u.y).
  for (float degrees : {9.0f, 1.0f}) {
    const Cone cone = Cone::fromAngle(degrees * kPi / 180.0f);
    const int bins = 16, n = 100000;
    std::vector<double> counts(size_t(bins * bins), 0.0);
    Rng rng(10);
    for (int i = 0; i < n; ++i) {
      const glm::vec3 w = sampleUniformCone(rng.uniform2(), cone);
      ASSERT_GE(w.z, cone.cosTheta() - 1e-6f);
      const double sin2 = double(w.x) * w.x + double(w.y) * w.y;
      const double oneMinusCos = sin2 / (1.0 + double(w.z));  // 1 - cos without cancellation
      double phi = std::atan2(double(w.y), double(w.x));
      if (phi < 0) phi += 2.0 * std::numbers::pi;
      const int a = std::clamp(int(oneMinusCos / double(cone.oneMinusCos) * bins), 0, bins - 1);
      const int b = std::clamp(int(phi / (2.0 * std::numbers::pi) * bins), 0, bins - 1);
      counts[size_t(a * bins + b)] += 1;
    }
    double chi2 = 0;
    const double expected = double(n) / (bins * bins);
    for (double c : counts) chi2 += (c - expected) * (c - expected) / expected;
    EXPECT_GT(test::chiSquareTail(chi2, bins * bins - 1), kSignificance) << degrees << " deg, chi2 " << chi2;
  }
}

// 1 - cos theta of a unit direction about +z, in double and without cancellation at either pole.
double oneMinusCosOf(const glm::vec3& w) {
  const double z = w.z, sin2 = double(w.x) * w.x + double(w.y) * w.y;
  return z > 0.0 ? sin2 / (1.0 + z) : 1.0 - z;
}

TEST(Warps, ConePdfIsOneOverItsSolidAngleDownToTinyCones) {
  // pdf = 1 / (2 pi (1 - cos theta)), with 1 - cos theta in double, to 1e-5 (float rounding is about
  // 3e-7). Taken from cos theta in float, the pdf was 150x too large at 1e-3 degrees (the cosine
  // rounds to 1), 2 % off at 0.1 degrees and 1e-4 at 1 degree.
  for (double degrees : {1e-3, 3e-3, 0.01, 0.1, 1.0, 9.0, 30.0, 90.0, 150.0, 180.0}) {
    const float theta = float(degrees * std::numbers::pi / 180.0);
    const double expected = 1.0 / (2.0 * std::numbers::pi * (1.0 - std::cos(double(theta))));
    const double pdf = uniformConePdf(Cone::fromAngle(theta));
    EXPECT_NEAR(pdf / expected, 1.0, 1e-5) << degrees << " deg: pdf " << pdf << ", expected " << expected;
  }
  EXPECT_TRUE(std::isfinite(uniformConePdf(Cone::fromAngle(0.0f))));
}

TEST(Warps, TinySmallAndLargeConesSampleUniformlyInside) {
  // Inverted to the unit square (1 - cos theta over the cone's, phi over 2 pi) the samples of a
  // uniform cone are uniform: 8x8 bins, chi-square; and none lies outside the cone.
  for (double degrees : {1e-3, 0.1, 60.0, 150.0}) {
    const Cone cone = Cone::fromAngle(float(degrees * std::numbers::pi / 180.0));
    const double oneMinusCosMax = 1.0 - std::cos(degrees * std::numbers::pi / 180.0);
    const int bins = 8, n = 32000;
    std::vector<double> counts(size_t(bins * bins), 0.0);
    Rng rng(5);
    double outside = 0.0;
    for (int i = 0; i < n; ++i) {
      const glm::vec3 w = sampleUniformCone(rng.uniform2(), cone);
      ASSERT_NEAR(glm::length(w), 1.0f, 1e-5f);
      const double a = oneMinusCosOf(w) / oneMinusCosMax;
      outside = std::max(outside, a - 1.0);
      double phi = std::atan2(double(w.y), double(w.x));
      if (phi < 0) phi += 2.0 * std::numbers::pi;
      const int ia = std::clamp(int(a * bins), 0, bins - 1);
      const int ib = std::clamp(int(phi / (2.0 * std::numbers::pi) * bins), 0, bins - 1);
      counts[size_t(ia * bins + ib)] += 1;
    }
    EXPECT_LE(outside, 1e-5) << degrees << " deg: a sample lies outside the cone";
    double chi2 = 0;
    const double expected = double(n) / (bins * bins);
    for (double c : counts) chi2 += (c - expected) * (c - expected) / expected;
    EXPECT_GT(test::chiSquareTail(chi2, bins * bins - 1), kSignificance) << degrees << " deg, chi2 " << chi2;
  }
}

// 2D binning on the unit square for warps to the disk and the triangle.
template <typename Fn, typename Inside>
double chiSquare2d(Fn sample, Inside inside, double area, int bins, int n) {
  std::vector<double> observed(size_t(bins * bins), 0.0), expected(size_t(bins * bins), 0.0);
  for (int i = 0; i < n; ++i) {
    const glm::vec2 p = sample();
    const int x = std::clamp(int(p.x * bins), 0, bins - 1), y = std::clamp(int(p.y * bins), 0, bins - 1);
    observed[size_t(y * bins + x)] += 1;
  }
  constexpr int kSub = 16;
  for (int y = 0; y < bins; ++y)
    for (int x = 0; x < bins; ++x) {
      int in = 0;
      for (int a = 0; a < kSub; ++a)
        for (int b = 0; b < kSub; ++b) in += inside(glm::vec2((x + (a + 0.5) / kSub) / bins, (y + (b + 0.5) / kSub) / bins));
      expected[size_t(y * bins + x)] = double(in) / (kSub * kSub) / (bins * bins) / area * n;
    }
  double chi2 = 0;
  int dof = -1;
  for (size_t k = 0; k < observed.size(); ++k) {
    if (expected[k] < 5) {
      EXPECT_LE(observed[k], expected[k] + 30) << "bin " << k;  // edge bins: only a loose check
      continue;
    }
    chi2 += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
    ++dof;
  }
  return test::chiSquareTail(chi2, dof);
}

// The warps' polynomials against double-precision libm over their whole domains, densely: within
// 2.5e-7 absolute (about two float ulps at 1), so the warps keep their accuracy.
TEST(FastTrig, MatchesLibmOverItsDomain) {
  constexpr int kSteps = 1 << 20;
  double worstSin = 0.0, worstCos = 0.0, worstAtan = 0.0;
  for (int i = 0; i <= kSteps; ++i) {
    const float t = 2.0f * float(i) / float(kSteps);  // quarter turns in [0, 2]
    const fast::SinCos f = fast::sinCosQuarterTurns(t);
    const double angle = std::numbers::pi / 4.0 * double(t);
    worstSin = std::max(worstSin, std::abs(double(f.sin) - std::sin(angle)));
    worstCos = std::max(worstCos, std::abs(double(f.cos) - std::cos(angle)));
    const float x = std::cos(float(angle)), y = std::sin(float(angle));  // every octant-folding case of atan2
    worstAtan = std::max(worstAtan, std::abs(double(fast::atan2Quadrant(y, x)) - std::atan2(double(y), double(x))));
    const float a = float(i) / float(kSteps);
    worstAtan = std::max(worstAtan, std::abs(double(fast::atanUnit(a)) - std::atan(double(a))));
  }
  EXPECT_LT(worstSin, 2.5e-7);
  EXPECT_LT(worstCos, 2.5e-7);
  EXPECT_LT(worstAtan, 2.5e-7);
  EXPECT_EQ(fast::atan2Quadrant(0.0f, 0.0f), 0.0f);
  EXPECT_EQ(fast::atan2Quadrant(0.0f, 2.0f), 0.0f);
  EXPECT_NEAR(fast::atan2Quadrant(3.0f, 0.0f), std::numbers::pi / 2.0, 1e-7);
  EXPECT_NEAR(fast::sinCosOctant(-0.5f).sin, std::sin(-0.5), 1e-7);
}

TEST(Warps, ConcentricDiskIsUniform) {
  Rng rng(6);
  const double p = chiSquare2d([&] { return 0.5f * (sampleConcentricDisk(rng.uniform2()) + 1.0f); },
                               [](glm::vec2 q) { return glm::length(2.0f * q - 1.0f) <= 1.0f; }, kPi / 4.0, 24, 200000);
  EXPECT_GT(p, kSignificance);
}

TEST(Warps, TriangleBarycentricsAreUniform) {
  Rng rng(7);
  const double p = chiSquare2d([&] { return sampleUniformTriangle(rng.uniform2()); },
                               [](glm::vec2 q) { return q.x + q.y <= 1.0f; }, 0.5, 24, 200000);
  EXPECT_GT(p, kSignificance);
}

TEST(EqualAreaMap, UniformSquareIsUniformSphere) {
  Rng rng(11);
  const auto r = test::chiSquareSphere([&] { return equalAreaSquareToSphere(rng.uniform2()); },
                                       [](const glm::vec3&) { return double(uniformSpherePdf()); }, 200000);
  EXPECT_GT(r.pValue, kSignificance) << r.report;
}

TEST(EqualAreaMap, InverseRoundTripsAndCellsHoldEqualShares) {
  Rng rng(12);
  for (int i = 0; i < 100000; ++i) {
    const glm::vec2 p = rng.uniform2();
    const glm::vec3 w = equalAreaSquareToSphere(p);
    ASSERT_NEAR(glm::length(w), 1.0f, 1e-5f);
    const glm::vec2 q = equalAreaSphereToSquare(w);
    ASSERT_NEAR(q.x, p.x, 2e-5f) << p.x << "," << p.y;
    ASSERT_NEAR(q.y, p.y, 2e-5f) << p.x << "," << p.y;
  }
  // Uniform directions fall into the cells of an 8x8 grid in equal shares (chi-square, 63 dof).
  constexpr int kRes = 8, kCount = 640000;
  std::vector<int> counts(kRes * kRes, 0);
  for (int i = 0; i < kCount; ++i) ++counts[size_t(equalAreaCell(sampleUniformSphere(rng.uniform2()), kRes))];
  double statistic = 0.0;
  const double expected = double(kCount) / (kRes * kRes);
  for (int c : counts) statistic += (c - expected) * (c - expected) / expected;
  EXPECT_GT(test::chiSquareTail(statistic, kRes * kRes - 1), kSignificance) << statistic;
  // The poles and the folds of the octahedron map where they should.
  EXPECT_NEAR(equalAreaSquareToSphere({0.5f, 0.5f}).z, 1.0f, 1e-6f);
  EXPECT_NEAR(equalAreaSquareToSphere({0.0f, 0.0f}).z, -1.0f, 1e-6f);
  EXPECT_NEAR(equalAreaSquareToSphere({1.0f, 0.5f}).z, 0.0f, 1e-6f);
}

TEST(Distribution1D, SamplesFollowWeightsAndSkipZeros) {
  const std::vector<float> w = {0.0f, 1.0f, 3.0f, 0.0f, 0.5f, -2.0f, NAN, 2.5f, INFINITY, 0.0f};
  const Distribution1D d(w);
  ASSERT_FALSE(d.empty());
  EXPECT_DOUBLE_EQ(d.total(), 7.0);
  std::vector<double> counts(w.size(), 0.0);
  Rng rng(8);
  const int n = 200000;
  double chi2 = 0;
  for (int i = 0; i < n; ++i) {
    float pmf = 0, remapped = 0;
    const size_t k = d.sample(rng.uniform(), &pmf, &remapped);
    ASSERT_LT(k, w.size());
    ASSERT_GT(pmf, 0.0f) << "picked zero-weight index " << k;
    ASSERT_FLOAT_EQ(pmf, d.pmf(k));
    ASSERT_GE(remapped, 0.0f);
    ASSERT_LT(remapped, 1.0f);
    counts[k] += 1;
  }
  int dof = -1;
  for (size_t k = 0; k < w.size(); ++k) {
    const double expected = d.pmf(k) * n;
    if (expected == 0) {
      EXPECT_EQ(counts[k], 0) << k;
      continue;
    }
    chi2 += (counts[k] - expected) * (counts[k] - expected) / expected;
    ++dof;
  }
  EXPECT_GT(test::chiSquareTail(chi2, dof), kSignificance) << "chi2 " << chi2;
  EXPECT_NEAR(d.pmf(2), 3.0f / 7.0f, 1e-6f);
}

TEST(Distribution1D, RemappedUniformIsUniform) {
  const std::vector<float> w = {1.0f, 5.0f, 0.0f, 2.0f};
  const Distribution1D d(w);
  Rng rng(9);
  std::vector<double> bins(20, 0.0);
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    float r = 0;
    d.sample(rng.uniform(), nullptr, &r);
    bins[std::min(size_t(r * 20), size_t(19))] += 1;
  }
  double chi2 = 0;
  for (double b : bins) chi2 += (b - n / 20.0) * (b - n / 20.0) / (n / 20.0);
  EXPECT_GT(test::chiSquareTail(chi2, 19), kSignificance);
}

TEST(Distribution1D, EmptyAndAllZero) {
  EXPECT_TRUE(Distribution1D().empty());
  const std::vector<float> zeros(5, 0.0f);
  EXPECT_TRUE(Distribution1D(zeros).empty());
  const std::vector<float> one = {4.0f};
  const Distribution1D d(one);
  float pmf = 0;
  EXPECT_EQ(d.sample(0.999999f, &pmf), 0u);
  EXPECT_FLOAT_EQ(pmf, 1.0f);
}

TEST(Rng, SameStreamSameNumbersAndUniformRange) {
  Rng a = Rng::forSample(3, 1234, 7), b = Rng::forSample(3, 1234, 7), c = Rng::forSample(3, 1234, 8);
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    const float x = a.uniform();
    ASSERT_EQ(x, b.uniform());
    ASSERT_GE(x, 0.0f);
    ASSERT_LT(x, 1.0f);
    differs |= x != c.uniform();
  }
  EXPECT_TRUE(differs);
}

}  // namespace
}  // namespace vpl
