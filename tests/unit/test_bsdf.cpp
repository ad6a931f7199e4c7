// The BSDF: sampling matches its pdf (chi-square), the pdf integrates to one, reciprocity, energy;
// one BSDF may be read by several threads at once (the light matrix rows of LightSlice are).
#include <cmath>
#include <thread>
#include <vector>
#include "render/core/color.h"
#include "render/material/bsdf.h"
#include "render/sampling/rng.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

struct Case {
  const char* name;
  glm::vec3 diffuse, f0;
  float f90, alpha;
};

glm::vec3 directionWithCos(float cosTheta, float phi) {
  const float s = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  return {s * std::cos(phi), s * std::sin(phi), cosTheta};
}

Bsdf makeBsdf(const Case& c) {
  BsdfParams p;
  p.diffuse = c.diffuse;
  p.f0 = c.f0;
  p.f90 = c.f90;
  p.alpha = c.alpha;
  // A tilted shading frame, so world/local conversions are exercised too.
  return Bsdf(p, Frame::fromNormal(glm::normalize(glm::vec3(0.2f, 0.3f, 0.9f))));
}

std::vector<Case> cases() {
  std::vector<Case> out;
  for (float alpha : {0.05f, 0.2f, 0.5f, 1.0f}) {
    out.push_back({"diffuse", glm::vec3(0.8f), glm::vec3(0.0f), 0.0f, alpha});
    out.push_back({"metal", glm::vec3(0.0f), glm::vec3(0.9f, 0.6f, 0.5f), 1.0f, alpha});
    out.push_back({"dielectric", glm::vec3(0.7f, 0.5f, 0.3f), glm::vec3(0.04f), 1.0f, alpha});
  }
  return out;
}

TEST(Bsdf, SamplingMatchesPdf) {
  for (const Case& c : cases())
    for (float cosO : {0.9f, 0.5f, 0.1f}) {
      const Bsdf bsdf = makeBsdf(c);
      const glm::vec3 wo = bsdf.frame().toWorld(directionWithCos(cosO, 0.7f));
      Rng rng(42);
      auto sample = [&]() -> glm::vec3 {
        const float uLobe = rng.uniform();
        const auto s = bsdf.sample(wo, rng.uniform2(), uLobe);
        return s ? bsdf.frame().toLocal(s->wi) : glm::vec3(0.0f);
      };
      auto pdf = [&](const glm::vec3& wLocal) { return double(bsdf.pdf(wo, bsdf.frame().toWorld(wLocal))); };
      const int bins = c.alpha < 0.1f ? 128 : 48;
      const auto r = test::chiSquareSphere(sample, pdf, 200000, bins, 2 * bins, 8);
      EXPECT_GT(r.pValue, 1e-4) << c.name << " alpha " << c.alpha << " cosO " << cosO << ": " << r.report;
    }
}

TEST(Bsdf, PdfIntegratesToOneAndWeightIsEvalOverPdf) {
  for (const Case& c : cases())
    for (float cosO : {0.9f, 0.3f}) {
      const Bsdf bsdf = makeBsdf(c);
      const glm::vec3 wo = bsdf.frame().toWorld(directionWithCos(cosO, 1.3f));
      const double integral = test::integrateSphere(
          [&](const glm::vec3& w) { return double(bsdf.pdf(wo, bsdf.frame().toWorld(w))); }, 1024, 1024);
      // Visible-normal samples reflected below the horizon are rejected (the path ends there), so the
      // pdf integrates to the probability that sample() returns a direction, not to 1.
      Rng rng(7);
      int failures = 0;
      const int n = 200000;
      for (int i = 0; i < n; ++i) {
        const float uLobe = rng.uniform();
        failures += !bsdf.sample(wo, rng.uniform2(), uLobe);
      }
      const double accepted = 1.0 - double(failures) / n;
      // Sharp lobes need a finer grid; 2% covers alpha 0.05 at this resolution.
      EXPECT_NEAR(integral, accepted, c.alpha < 0.1f ? 0.02 : 0.006) << c.name << " alpha " << c.alpha << " cosO " << cosO;
      if (c.diffuse != glm::vec3(0.0f) && c.f0 == glm::vec3(0.0f)) EXPECT_EQ(failures, 0);

      for (int i = 0; i < 200; ++i) {
        const float uLobe = rng.uniform();
        const auto s = bsdf.sample(wo, rng.uniform2(), uLobe);
        if (!s) continue;
        const glm::vec3 expected = bsdf.eval(wo, s->wi) / bsdf.pdf(wo, s->wi);
        for (int k = 0; k < 3; ++k) ASSERT_NEAR(s->weight[k], expected[k], 1e-3f * (1.0f + expected[k]));  // world<->local rounding
        ASSERT_NEAR(s->pdf, bsdf.pdf(wo, s->wi), 1e-3f * s->pdf);
      }
    }
}

TEST(Bsdf, Reciprocity) {
  Rng rng(3);
  for (const Case& c : cases()) {
    const Bsdf bsdf = makeBsdf(c);
    for (int i = 0; i < 200; ++i) {
      const glm::vec3 a = bsdf.frame().toWorld(directionWithCos(0.02f + 0.98f * rng.uniform(), 6.283f * rng.uniform()));
      const glm::vec3 b = bsdf.frame().toWorld(directionWithCos(0.02f + 0.98f * rng.uniform(), 6.283f * rng.uniform()));
      const float cosA = glm::dot(a, bsdf.frame().n), cosB = glm::dot(b, bsdf.frame().n);
      const glm::vec3 fab = bsdf.eval(a, b) / cosB, fba = bsdf.eval(b, a) / cosA;
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(fab[k], fba[k], 1e-3f * (1.0f + fab[k])) << c.name;
    }
  }
}

// evalPdf is what a light sample and a join ask for: it must give eval, pdf and the reverse pdf
// exactly, so that the tracer's images stay the same whichever of them it calls.
TEST(Bsdf, EvalPdfGivesEvalAndBothDensitiesExactly) {
  Rng rng(11);
  std::vector<Case> all = cases();
  all.push_back({"lambert", glm::vec3(0.6f, 0.3f, 0.1f), glm::vec3(0.0f), 0.0f, 0.5f});
  for (const Case& c : all) {
    const Bsdf bsdf = makeBsdf(c);
    for (int i = 0; i < 300; ++i) {
      // Both hemispheres for each direction: below the surface everything is 0.
      const glm::vec3 a = bsdf.frame().toWorld(directionWithCos(-0.2f + 1.2f * rng.uniform(), 6.283f * rng.uniform()));
      const glm::vec3 b = bsdf.frame().toWorld(directionWithCos(-0.2f + 1.2f * rng.uniform(), 6.283f * rng.uniform()));
      Bsdf bound = bsdf;
      bound.bindOutgoing(a);
      for (const Bsdf* at : {&bsdf, static_cast<const Bsdf*>(&bound)}) {
        const Bsdf::Evaluation e = at->evalPdf(a, b);
        ASSERT_EQ(e.f, bsdf.eval(a, b)) << c.name;
        ASSERT_EQ(e.pdf, bsdf.pdf(a, b)) << c.name;
        ASSERT_EQ(e.pdfReverse, bsdf.pdf(b, a)) << c.name;
      }
    }
  }
}

// Directional albedo by importance sampling: mean of the sample weights (the estimator the path tracer uses).
glm::dvec3 albedo(const Bsdf& bsdf, const glm::vec3& wo, int n, uint64_t seed) {
  Rng rng(seed);
  glm::dvec3 sum(0.0);
  for (int i = 0; i < n; ++i) {
    const float uLobe = rng.uniform();
    if (const auto s = bsdf.sample(wo, rng.uniform2(), uLobe)) sum += glm::dvec3(s->weight);
  }
  return sum / double(n);
}

TEST(Bsdf, NeverReflectsMoreThanItReceives) {
  for (float alpha : {Bsdf::kMinAlpha, 0.05f, 0.3f, 1.0f})
    for (float f0 : {0.0f, 0.04f, 0.5f, 1.0f})
      for (float cosO : {1.0f, 0.5f, 0.05f}) {
        const Case c{"white", glm::vec3(1.0f), glm::vec3(f0), 1.0f, alpha};
        const Bsdf bsdf = makeBsdf(c);
        const glm::vec3 wo = bsdf.frame().toWorld(directionWithCos(cosO, 0.0f));
        const glm::dvec3 a = albedo(bsdf, wo, 40000, 11);
        EXPECT_LE(a.x, 1.01) << "alpha " << alpha << " f0 " << f0 << " cosO " << cosO;
        EXPECT_TRUE(std::isfinite(a.x));
      }
}

TEST(Bsdf, WhiteDielectricKeepsNearlyAllEnergy) {
  // Diffuse 1 under a 4% coating: Kelemen coupling gives albedo E + (1 - E) = 1 up to table error.
  for (float alpha : {0.1f, 0.5f, 1.0f})
    for (float cosO : {0.9f, 0.4f}) {
      const Bsdf bsdf = makeBsdf({"white", glm::vec3(1.0f), glm::vec3(0.04f), 1.0f, alpha});
      const glm::dvec3 a = albedo(bsdf, bsdf.frame().toWorld(directionWithCos(cosO, 0.0f)), 100000, 5);
      EXPECT_NEAR(a.y, 1.0, 0.03) << "alpha " << alpha << " cosO " << cosO;
    }
}

TEST(Bsdf, PureLambertianWhenNoSpecular) {
  const Bsdf bsdf = makeBsdf({"lambert", glm::vec3(0.6f, 0.3f, 0.1f), glm::vec3(0.0f), 0.0f, 0.5f});
  Rng rng(9);
  for (int i = 0; i < 100; ++i) {
    const glm::vec3 wo = bsdf.frame().toWorld(directionWithCos(0.05f + 0.95f * rng.uniform(), 6.28f * rng.uniform()));
    const float cosI = 0.05f + 0.95f * rng.uniform();
    const glm::vec3 wi = bsdf.frame().toWorld(directionWithCos(cosI, 6.28f * rng.uniform()));
    const glm::vec3 f = bsdf.eval(wo, wi);
    const glm::vec3 expected = glm::vec3(0.6f, 0.3f, 0.1f) / 3.14159265f * cosI;
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(f[k], expected[k], 1e-5f);
    // The Lambertian shortcuts agree with each other, bound to wo or not, and see wo's side.
    Bsdf bound = bsdf;
    bound.bindOutgoing(wo);
    const Bsdf::Evaluation both = bsdf.evalPdf(wo, wi);
    ASSERT_EQ(both.f, f);
    ASSERT_EQ(both.pdf, bsdf.pdf(wo, wi));
    ASSERT_NEAR(both.pdf, cosI / 3.14159265f, 1e-5f);
    ASSERT_EQ(bound.eval(wo, wi), f);
    ASSERT_EQ(bound.pdf(wo, wi), both.pdf);
    const glm::vec3 below = bsdf.frame().toWorld(directionWithCos(-0.5f, 1.0f));
    ASSERT_EQ(bsdf.eval(below, wi), glm::vec3(0.0f));
    ASSERT_EQ(bsdf.pdf(below, wi), 0.0f);
    ASSERT_FALSE(bsdf.sample(below, glm::vec2(0.3f, 0.6f)).has_value());
  }
  EXPECT_FALSE(bsdf.isNearSpecular());
}

TEST(Bsdf, ExtremesStayFinite) {
  for (float alpha : {0.0f, Bsdf::kMinAlpha, 1.0f})
    for (float cosO : {1.0f, 1e-4f, 0.0f, -0.3f}) {
      const Bsdf bsdf = makeBsdf({"metal", glm::vec3(0.0f), glm::vec3(1.0f), 1.0f, alpha});
      const glm::vec3 wo = bsdf.frame().toWorld(directionWithCos(cosO, 0.4f));
      Rng rng(1);
      for (int i = 0; i < 1000; ++i) {
        const float uLobe = rng.uniform();
        const auto s = bsdf.sample(wo, rng.uniform2(), uLobe);
        if (!s) continue;
        ASSERT_TRUE(isFiniteNonNegative(s->weight)) << alpha << " " << cosO;
        ASSERT_TRUE(std::isfinite(s->pdf) && s->pdf > 0.0f);
        ASSERT_TRUE(isFiniteNonNegative(bsdf.eval(wo, s->wi)));
      }
    }
  EXPECT_TRUE(makeBsdf({"mirror", glm::vec3(0.0f), glm::vec3(1.0f), 1.0f, 0.0f}).isNearSpecular());
}

// Plain std::threads, so that the ThreadSanitizer run (tests/e2e/tsan_session.sh) sees every access.
TEST(Bsdf, OneBsdfEvaluatesTheSameFromSeveralThreadsAtOnce) {
  const Bsdf shared = makeBsdf({"dielectric", glm::vec3(0.7f, 0.5f, 0.3f), glm::vec3(0.04f), 1.0f, 0.3f});
  const glm::vec3 wi = shared.frame().toWorld(directionWithCos(0.6f, 1.0f));
  constexpr int kThreads = 4, kSteps = 2000;
  std::vector<std::vector<glm::vec3>> expected(kThreads), got(kThreads, std::vector<glm::vec3>(kSteps));
  auto wo = [&](int t, int i) { return shared.frame().toWorld(directionWithCos(0.05f + 0.9f * float((i * 7 + t * 13) % 97) / 96.0f, 2.0f)); };
  for (int t = 0; t < kThreads; ++t)
    for (int i = 0; i < kSteps; ++i) expected[size_t(t)].push_back(Bsdf(shared).eval(wo(t, i), wi));
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < kSteps; ++i) got[size_t(t)][size_t(i)] = shared.eval(wo(t, i), wi);
    });
  for (std::thread& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t)
    for (int i = 0; i < kSteps; ++i) ASSERT_EQ(got[size_t(t)][size_t(i)], expected[size_t(t)][size_t(i)]) << t << " " << i;
}

TEST(Bsdf, FresnelF0FollowsGltfExtensions) {
  // Dielectric, ior 1.5: 0.04. specularFactor 0: no specular. Metal: the base colour.
  EXPECT_NEAR(fresnelF0(glm::vec3(0.5f), 0.0f, 1.5f, 1.0f, glm::vec3(1.0f)).x, 0.04f, 1e-6f);
  EXPECT_EQ(fresnelF0(glm::vec3(0.5f), 0.0f, 1.5f, 0.0f, glm::vec3(1.0f)), glm::vec3(0.0f));
  EXPECT_EQ(fresnelF90(0.0f, 0.0f), 0.0f);
  EXPECT_NEAR(fresnelF0(glm::vec3(0.9f, 0.5f, 0.2f), 1.0f, 1.5f, 1.0f, glm::vec3(1.0f)).z, 0.2f, 1e-6f);
  EXPECT_NEAR(fresnelF0(glm::vec3(0.5f), 0.0f, 2.0f, 1.0f, glm::vec3(1.0f)).x, 1.0f / 9.0f, 1e-6f);
}

}  // namespace
}  // namespace vpl
