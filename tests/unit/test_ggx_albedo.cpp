// The magnitude of the GGX lobe against an anchor that does not come from this renderer: the
// directional albedo E(mu) = integral of f(wo, wi) cos(theta_i) dwi, computed here by a deterministic
// quadrature of formulas written out in this file from the glTF 2.0 specification (Appendix B:
// Trowbridge-Reitz D, height-correlated Smith visibility V in the spec's own algebraic form,
// Schlick's Fresnel with F90) and Walter et al. 2007 — not from render/material.
//
// What is read from the project is only its parameterisation: alpha = roughness^2 (glTF), f0 =
// baseColor and f90 = 1 for a metal, no multiple-scattering compensation on the specular lobe. A
// metal (metallic 1) has no diffuse lobe, so its albedo is the single-scattering GGX albedo and is
// anchored directly. A dielectric couples a Lambertian lobe to the specular one (Kelemen &
// Szirmay-Kalos 2001, render/material/bsdf.cpp): its total albedo has the closed form
// E_s(mu) + rho (1 - E_s(mu)) (the coupled diffuse lobe integrates to rho (1 - E_s(mu)) whatever
// E_s is), which is anchored with the independent E_s.
//
// Three estimates are compared with the independent table:
//   (a) the project's Bsdf::eval integrated by the same quadrature,
//   (b) the Monte Carlo mean of the project's sample weights eval * cos / pdf (what the path tracer
//       multiplies by), within 4.5 of its own standard errors,
//   (c) a rendered plane under a uniform white sky through the whole pipeline (glTF material ->
//       BSDF parameters -> integrator): radiance E(mu) exactly, in brdf, mis and preview modes.
// A rough metal 5 % too dark fails (a), (b) and (c) by many tolerances (checked by scaling the lobe).
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>
#include "render/material/bsdf.h"
#include "render/material/specular_albedo_integral.h"
#include "render/sampling/rng.h"
#include "render/session/render_job.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// ---- Independent microfacet model (glTF 2.0 spec, Appendix B; double precision) -------------------
namespace indep {

// Trowbridge-Reitz / GGX normal distribution, alpha = roughness^2.
double D(double nh, double alpha) {
  if (nh <= 0.0) return 0.0;
  const double a2 = alpha * alpha;
  const double d = nh * nh * (a2 - 1.0) + 1.0;
  return a2 / (kPiD * d * d);
}

// Height-correlated Smith visibility V = G2 / (4 |n.l| |n.v|), in the form the glTF spec writes it.
double V(double nl, double nv, double alpha) {
  const double a2 = alpha * alpha;
  const double ggxv = nl * std::sqrt(nv * nv * (1.0 - a2) + a2);
  const double ggxl = nv * std::sqrt(nl * nl * (1.0 - a2) + a2);
  const double s = ggxv + ggxl;
  return s > 0.0 ? 0.5 / s : 0.0;
}

double schlick(double f0, double f90, double vh) {
  const double m = std::clamp(1.0 - vh, 0.0, 1.0);
  return f0 + (f90 - f0) * m * m * m * m * m;
}

// f(wo, wi) cos(theta_i) of the specular lobe, local frame (normal +z).
double specular(const glm::dvec3& wo, const glm::dvec3& wi, double alpha, double f0, double f90) {
  if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
  const glm::dvec3 h = glm::normalize(wo + wi);
  return schlick(f0, f90, glm::dot(wo, h)) * D(h.z, alpha) * V(wi.z, wo.z, alpha) * wi.z;
}

}  // namespace indep

// ---- Deterministic quadrature over the hemisphere --------------------------------------------------
// Two grids with a balance-heuristic partition of unity, so that both a lobe a few thousandths of a
// radian wide and a cosine tail are resolved:
//   grid S: half vectors h by the inverse CDF of D(h) cos(theta_h), tan^2(theta_h) = alpha^2 u/(1-u),
//           phi uniform (an analytic change of variables), wi = reflect(wo, h); its density in wi is
//           pS = D(h) cos(theta_h) / (4 wo.h);
//   grid C: wi by the polar map of the cosine-weighted hemisphere, density pC = cos(theta_i) / pi.
// integral g = mean_S[g / (pS + pC)] + mean_C[g / (pS + pC)] (midpoint rule on n x n cells of each).
// The integrands are continuous (G2 -> 0 at the horizon), so the midpoint error falls as 1/n^2; the
// caller estimates it from the difference to the same rule at n/2.
double hemisphereIntegral(const glm::dvec3& wo, double alpha, int n, const std::function<double(const glm::dvec3&)>& g) {
  auto pS = [&](const glm::dvec3& wi) {
    if (wi.z <= 0.0) return 0.0;
    const glm::dvec3 h = glm::normalize(wo + wi);
    const double oh = glm::dot(wo, h);
    return oh > 0.0 ? indep::D(h.z, alpha) * h.z / (4.0 * oh) : 0.0;
  };
  auto pC = [](const glm::dvec3& wi) { return wi.z > 0.0 ? wi.z / kPiD : 0.0; };
  double sumS = 0.0, sumC = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = (i + 0.5) / n, v = (j + 0.5) / n;
      const double phi = 2.0 * kPiD * v;
      {  // grid S
        const double tan2 = alpha * alpha * u / (1.0 - u);
        const double cosH = 1.0 / std::sqrt(1.0 + tan2), sinH = std::sqrt(std::max(0.0, 1.0 - cosH * cosH));
        const glm::dvec3 h(sinH * std::cos(phi), sinH * std::sin(phi), cosH);
        const double oh = glm::dot(wo, h);
        const glm::dvec3 wi = 2.0 * oh * h - wo;
        if (oh > 0.0 && wi.z > 0.0) sumS += g(wi) / (pS(wi) + pC(wi));
      }
      {  // grid C
        const double r = std::sqrt(u);
        const glm::dvec3 wi(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u)));
        if (wi.z > 0.0) sumC += g(wi) / (pS(wi) + pC(wi));
      }
    }
  return (sumS + sumC) / (double(n) * n);
}

glm::dvec3 viewDirection(double mu) { return {std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu}; }

struct Quadrature {
  double value = 0.0, error = 0.0;  // error: |I(n) - I(n/2)|, an upper estimate of |I(n) - I| for a 1/n^2 rule
};
Quadrature integrate(double mu, double alpha, const std::function<double(const glm::dvec3&)>& g, int n = 384) {
  const glm::dvec3 wo = viewDirection(mu);
  const double fine = hemisphereIntegral(wo, alpha, n, g), coarse = hemisphereIntegral(wo, alpha, n / 2, g);
  return {fine, std::abs(fine - coarse)};
}

// Independent single-scattering albedo of the GGX lobe with Schlick Fresnel (f0, f90).
Quadrature independentAlbedo(double mu, double roughness, double f0, double f90) {
  const double alpha = roughness * roughness;
  return integrate(mu, alpha, [&](const glm::dvec3& wi) { return indep::specular(viewDirection(mu), wi, alpha, f0, f90); });
}

// The project's BSDF for a glTF material as render/scene/render_scene.cpp builds it, identity frame.
Bsdf projectBsdf(const glm::vec3& baseColor, float metallic, float roughness) {
  BsdfParams p;
  p.diffuse = baseColor * (1.0f - metallic);
  p.f0 = fresnelF0(baseColor, metallic, 1.5f, 1.0f, glm::vec3(1.0f));
  p.f90 = fresnelF90(metallic, 1.0f);
  p.alpha = std::max(roughness * roughness, Bsdf::kMinAlpha);
  return Bsdf(p, Frame{});
}

Quadrature projectAlbedo(const Bsdf& bsdf, double mu, double roughness, int channel) {
  const glm::vec3 wo(viewDirection(mu));
  return integrate(mu, roughness * roughness, [&](const glm::dvec3& wi) { return double(bsdf.eval(wo, glm::vec3(wi))[channel]); });
}

struct MonteCarlo {
  glm::dvec3 mean{0.0}, error{0.0};  // error: standard error of the mean
};
MonteCarlo sampledAlbedo(const Bsdf& bsdf, double mu, int n, uint64_t seed) {
  const glm::vec3 wo(viewDirection(mu));
  Rng rng(seed);
  glm::dvec3 sum(0.0), sum2(0.0);
  for (int i = 0; i < n; ++i) {
    const float uLobe = rng.uniform();
    if (const auto s = bsdf.sample(wo, rng.uniform2(), uLobe)) {
      const glm::dvec3 w(s->weight);
      sum += w;
      sum2 += w * w;
    }
  }
  MonteCarlo m;
  m.mean = sum / double(n);
  m.error = glm::sqrt(glm::max(sum2 / double(n) - m.mean * m.mean, glm::dvec3(0.0)) / double(n));
  return m;
}

const double kRoughness[] = {0.1, 0.3, 0.6, 1.0};
const double kMu[] = {1.0, 0.5, 0.1};
// 4.5 standard errors: two-sided 7e-6 per comparison, under 1e-3 for every comparison in this file.
constexpr double kSigmas = 4.5;

// The quadrature itself, checked on integrals known in closed form: D(h) cos(theta_h) integrates to 1
// over the half vectors (the normalisation the change of variables relies on), and the cosine lobe
// to 1 over the hemisphere, for a sharp and a rough alpha and a grazing view.
TEST(GgxAlbedo, QuadratureIntegratesKnownIntegrals) {
  for (double roughness : {0.1, 1.0})
    for (double mu : {1.0, 0.1}) {
      const double alpha = roughness * roughness;
      const Quadrature cosine = integrate(mu, alpha, [](const glm::dvec3& wi) { return wi.z / kPiD; });
      EXPECT_NEAR(cosine.value, 1.0, 2e-4) << "roughness " << roughness << " mu " << mu;
      // In wi space: integral of pS(wi) over wi above the horizon equals the mass of half vectors whose
      // reflection stays above it; at normal incidence that is every h with theta_h < 45 degrees:
      // tan^2 < 1, u < 1/(1 + alpha^2) of the inverse CDF.
      if (mu == 1.0) {
        const glm::dvec3 wo(0, 0, 1);
        const Quadrature mass = integrate(mu, alpha, [&](const glm::dvec3& wi) {
          const glm::dvec3 h = glm::normalize(wo + wi);
          return indep::D(h.z, alpha) * h.z / (4.0 * glm::dot(wo, h));
        });
        EXPECT_NEAR(mass.value, 1.0 / (1.0 + alpha * alpha), 2e-4) << "roughness " << roughness;
      }
    }
}

// (a) and (b) for a white metal and a grey one (f0 = 0.5, so Schlick's Fresnel varies over the lobe).
TEST(GgxAlbedo, MetalAlbedoMatchesIndependentQuadratureAndSampledWeights) {
  for (double base : {1.0, 0.5})
    for (double roughness : kRoughness)
      for (double mu : kMu) {
        const Quadrature ref = independentAlbedo(mu, roughness, base, 1.0);
        const Bsdf bsdf = projectBsdf(glm::vec3(float(base)), 1.0f, float(roughness));
        const Quadrature evalIntegral = projectAlbedo(bsdf, mu, roughness, 1);
        const MonteCarlo mc = sampledAlbedo(bsdf, mu, 200000, 17);
        std::printf("metal base %.1f roughness %.1f mu %.1f: independent %.5f (quadrature +-%.1e)  eval %.5f  sampled %.5f +- %.5f\n",
                    base, roughness, mu, ref.value, ref.error, evalIntegral.value, mc.mean.y, mc.error.y);
        // (a) Same quadrature, so only float rounding of eval (D's denominator near 1e-4 at alpha 0.01)
        // and the two quadrature errors separate them: 0.2 % + the estimated errors.
        const double tolA = 2e-3 * ref.value + ref.error + evalIntegral.error;
        EXPECT_NEAR(evalIntegral.value, ref.value, tolA) << "eval: base " << base << " roughness " << roughness << " mu " << mu;
        // (b) Monte Carlo against the table: its standard error, plus the quadrature's.
        const double tolB = kSigmas * mc.error.y + ref.error + 1e-4;
        EXPECT_NEAR(mc.mean.y, ref.value, tolB) << "sampled: base " << base << " roughness " << roughness << " mu " << mu;
        // The tolerances stay below half of the 5 % that must fail.
        EXPECT_LT(std::max(tolA, tolB), 0.025 * ref.value) << "roughness " << roughness << " mu " << mu;
      }
}

// A coloured metal: each channel has its own f0, so Fresnel per channel is pinned as well.
TEST(GgxAlbedo, ColouredMetalAlbedoIsPerChannelFresnel) {
  const glm::vec3 base(0.95f, 0.64f, 0.54f);  // copper-like
  for (double roughness : {0.3, 0.6})
    for (double mu : {1.0, 0.5}) {
      const Bsdf bsdf = projectBsdf(base, 1.0f, float(roughness));
      const MonteCarlo mc = sampledAlbedo(bsdf, mu, 100000, 5);
      for (int k = 0; k < 3; ++k) {
        const Quadrature ref = independentAlbedo(mu, roughness, base[k], 1.0);
        const Quadrature evalIntegral = projectAlbedo(bsdf, mu, roughness, k);
        EXPECT_NEAR(evalIntegral.value, ref.value, 2e-3 * ref.value + ref.error + evalIntegral.error)
            << "channel " << k << " roughness " << roughness << " mu " << mu;
        EXPECT_NEAR(mc.mean[k], ref.value, kSigmas * mc.error[k] + ref.error + 1e-4)
            << "channel " << k << " roughness " << roughness << " mu " << mu;
      }
    }
}

// Lambert coupled to the dielectric lobe (f0 0.04, f90 1): total albedo E_s + rho (1 - E_s). With
// rho = 1 that is 1 (a white dielectric is a furnace); the tolerance covers the project's tabulated
// E_s (32 x 32 entries of 32^2 samples, bilinear), which the coupling uses in place of the exact one.
TEST(GgxAlbedo, CoupledDielectricTotalAlbedoMatchesClosedForm) {
  for (double rho : {1.0, 0.5})
    for (double roughness : kRoughness)
      for (double mu : kMu) {
        const Quadrature es = independentAlbedo(mu, roughness, 0.04, 1.0);
        const double expected = es.value + rho * (1.0 - es.value);
        const Bsdf bsdf = projectBsdf(glm::vec3(float(rho)), 0.0f, float(roughness));
        const Quadrature evalIntegral = projectAlbedo(bsdf, mu, roughness, 1);
        const MonteCarlo mc = sampledAlbedo(bsdf, mu, 100000, 23);
        std::printf("dielectric rho %.1f roughness %.1f mu %.1f: closed form %.5f  eval %.5f  sampled %.5f +- %.5f\n", rho,
                    roughness, mu, expected, evalIntegral.value, mc.mean.y, mc.error.y);
        EXPECT_NEAR(evalIntegral.value, expected, 5e-3 + es.error + evalIntegral.error)
            << "rho " << rho << " roughness " << roughness << " mu " << mu;
        EXPECT_NEAR(mc.mean.y, expected, 5e-3 + kSigmas * mc.error.y + es.error)
            << "rho " << rho << " roughness " << roughness << " mu " << mu;
      }
}

// The renderer reads the table embedded in specular_albedo_values.inc, not the integral (which every
// process used to compute at start); the two must be the same floats. Without -ffast-math or FMA
// contraction the integral's float operations are the same in every build, so this asks for bits.
TEST(GgxAlbedo, EmbeddedTableIsTheIntegralBitForBit) {
  const SpecularAlbedoTable integral = integrateSpecularAlbedoTable();
  const SpecularAlbedoTable& embedded = embeddedSpecularAlbedoTable();
  const char* regenerate = "regenerate: build/tools/make_specular_albedo_table > render/material/specular_albedo_values.inc";
  for (size_t k = 0; k < integral.e.size(); ++k) {
    ASSERT_EQ(embedded.e[k].a, integral.e[k].a) << "entry " << k << "; " << regenerate;
    ASSERT_EQ(embedded.e[k].b, integral.e[k].b) << "entry " << k << "; " << regenerate;
  }
  for (size_t j = 0; j < integral.average.size(); ++j) {
    ASSERT_EQ(embedded.average[j].a, integral.average[j].a) << "row " << j << "; " << regenerate;
    ASSERT_EQ(embedded.average[j].b, integral.average[j].b) << "row " << j << "; " << regenerate;
  }
}

// ---- (c) Through the whole pipeline: a metal plane under a uniform white sky -----------------------
// Every point of a plane sees the whole upper hemisphere of sky and nothing else, so its radiance
// towards wo is E(mu) times the sky radiance exactly, at any path depth. The view is so narrow
// (yfov 0.004 rad) that mu varies by less than 0.2 % over the image.
SceneData metalPlane(const glm::vec3& baseColor, float roughness, double mu) {
  constexpr float kHalf = 1e4f;
  SceneData s;
  Material m;
  m.baseColor = baseColor;
  m.metallic = 1.0f;
  m.roughness = roughness;
  m.doubleSided = true;
  s.materials.push_back(m);
  MeshData plane;
  plane.name = "plane";
  plane.positions = {{-kHalf, 0, -kHalf}, {kHalf, 0, -kHalf}, {kHalf, 0, kHalf}, {-kHalf, 0, kHalf}};
  plane.indices = {0, 2, 1, 0, 3, 2};  // normal +y
  s.meshes.push_back(plane);
  s.boundsMin = glm::vec3(-kHalf, 0.0f, -kHalf);
  s.boundsMax = glm::vec3(kHalf, 1.0f, kHalf);
  CameraData camera;
  camera.eye = glm::vec3(0, 1, 0);
  const float sinT = float(mu), cosT = float(std::sqrt(std::max(0.0, 1.0 - mu * mu)));
  camera.target = camera.eye + glm::vec3(0.0f, -sinT, -cosT);  // wo.y = mu at the plane
  camera.up = cosT > 0.0f ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, -1);
  camera.yfov = 0.004f;
  s.camera = camera;
  return s;
}

TEST(GgxAlbedo, RenderedMetalPlaneUnderWhiteSkyShowsTheAlbedo) {
  const glm::vec3 base(1.0f, 0.5f, 0.2f);  // three Fresnel cases in one image
  uint64_t seed = 0;
  for (SamplingMode mode : {SamplingMode::Brdf, SamplingMode::Mis, SamplingMode::Preview})
    for (double roughness : {0.3, 0.6, 1.0})
      for (double mu : {1.0, 0.5, 0.1}) {
        // The preview lights by one uniform sky sample per pixel sample (no BSDF sampling to combine
        // with): at this budget its error is small enough only for the widest lobe.
        if (mode == SamplingMode::Preview && roughness < 1.0) continue;
        RenderJobSettings s;
        s.scenePath = "metal plane under sky (in memory)";
        s.mode = mode;
        s.width = 8;
        s.height = 8;
        s.spp = 1024;
        s.seed = ++seed;  // a stream of its own per image, so that the images' errors are independent
        s.tracer.maxDepth = 1;
        s.sky.explicitSky = true;
        s.sky.radiance = glm::vec3(1.0f);
        s.preview.vpl.count = 256;
        const RenderJobResult r = runRenderJob(s, metalPlane(base, float(roughness), mu));
        ASSERT_EQ(r.discarded, 0u);
        const double n = double(r.image.pixels.size());
        for (int k = 0; k < 3; ++k) {
          double sum = 0.0, sum2 = 0.0;
          for (const glm::vec3& p : r.image.pixels) {
            sum += p[k];
            sum2 += double(p[k]) * p[k];
          }
          const double mean = sum / n, error = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / (n - 1.0));
          const Quadrature ref = independentAlbedo(mu, roughness, base[k], 1.0);
          if (k == 0)
            std::printf("render %-7s roughness %.1f mu %.1f: independent %.4f rendered %.4f +- %.4f\n", modeName(mode),
                        roughness, mu, ref.value, mean, error);
          // Pixel means are independent, so their spread gives the standard error; 0.3 % covers the
          // spread of mu over the narrow view.
          EXPECT_NEAR(mean, ref.value, kSigmas * error + 3e-3 * ref.value + ref.error)
              << modeName(mode) << " channel " << k << " roughness " << roughness << " mu " << mu;
          EXPECT_LT(kSigmas * error, 0.025 * ref.value) << modeName(mode) << " roughness " << roughness << " mu " << mu;
        }
      }
}

}  // namespace
}  // namespace vpl
