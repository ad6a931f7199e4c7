// DESIGN.md §5 at the integrator level, on a case with an exact answer: an unbounded-looking plane
// under a uniform white sky. Every point of the plane sees the whole upper hemisphere of sky, so a
// Lambertian plane of albedo rho leaves radiance rho exactly, whatever the view angle; a mirror-like
// white metal leaves (nearly) the sky itself; no material may leave more than the sky. Checked in
// every mode at a grazing view (cosine ~1e-3) and a moderate one, at roughness 0 and 1, and with
// every VPL and cluster budget at 1.
#include <cmath>
#include "render/session/render_job.h"
#include "tests/unit/scene_builders.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

constexpr float kHalfSize = 1e4f;

// A square plane y = 0 of half-size 1e4 seen from height 1, the view tilted `tilt` radians below the
// horizon with a field of view so narrow that every pixel meets the plane at about that angle.
SceneData skyPlane(const Material& material, float tilt) {
  SceneData s;
  s.materials.push_back(material);
  MeshData plane;
  plane.name = "plane";
  plane.positions = {{-kHalfSize, 0, -kHalfSize}, {kHalfSize, 0, -kHalfSize}, {kHalfSize, 0, kHalfSize}, {-kHalfSize, 0, kHalfSize}};
  plane.indices = {0, 2, 1, 0, 3, 2};  // normal +y
  plane.material = 0;
  s.meshes.push_back(plane);
  s.boundsMin = glm::vec3(-kHalfSize, 0.0f, -kHalfSize);
  s.boundsMax = glm::vec3(kHalfSize, 1.0f, kHalfSize);
  CameraData camera;
  camera.eye = glm::vec3(0, 1, 0);
  camera.target = camera.eye + glm::vec3(0.0f, -std::sin(tilt), -std::cos(tilt));
  camera.yfov = 0.2f * tilt;
  s.camera = camera;
  return s;
}

Material whiteMetal(float roughness) {
  Material m;
  m.baseColor = glm::vec3(1.0f);
  m.metallic = 1.0f;
  m.roughness = roughness;
  m.doubleSided = true;
  return m;
}

struct Stats {
  double mean = 0.0, error = 0.0, max = 0.0;
  bool finite = true;
};

Stats render(const Material& material, float tilt, SamplingMode mode, bool budgetsAtOne = false) {
  RenderJobSettings s;
  s.scenePath = "sky plane (in memory)";
  s.mode = mode;
  s.width = 16;
  s.height = 16;
  s.spp = budgetsAtOne ? 1 : 32;
  s.tracer.maxDepth = budgetsAtOne ? 1 : 8;
  s.sky.explicitSky = true;
  s.sky.radiance = glm::vec3(1.0f);
  s.preview.vpl.count = budgetsAtOne ? 1 : 2048;
  if (budgetsAtOne) {
    test::setPreviewBudgetsToOne(s);
    s.guide.mutations = 1;
  }
  const RenderJobResult r = runRenderJob(s, skyPlane(material, tilt));
  Stats st;
  double sum = 0.0, sum2 = 0.0;
  for (const glm::vec3& p : r.image.pixels) {
    st.finite = st.finite && std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && p.x >= 0.0f;
    sum += p.y;
    sum2 += double(p.y) * p.y;
    st.max = std::max(st.max, double(p.y));
  }
  const double n = double(r.image.pixels.size());
  st.mean = sum / n;
  st.error = std::sqrt(std::max(0.0, sum2 / n - st.mean * st.mean) / n);
  EXPECT_EQ(r.discarded, 0u);
  return st;
}

const SamplingMode kModes[] = {SamplingMode::Brdf, SamplingMode::Mis, SamplingMode::Metropolis, SamplingMode::Mixture,
                               SamplingMode::Preview};
constexpr float kGrazing = 1e-3f, kModerate = 0.6f;

TEST(SkyPlane, LambertianPlaneIsAlbedoTimesSkyAtGrazingAndModerateViews) {
  for (float tilt : {kGrazing, kModerate})
    for (SamplingMode mode : kModes) {
      const Stats st = render(test::lambertian(0.5f), tilt, mode);
      ASSERT_TRUE(st.finite) << modeName(mode) << " tilt " << tilt;
      EXPECT_NEAR(st.mean, 0.5, 4.0 * st.error + 0.01) << modeName(mode) << " tilt " << tilt;
    }
}

TEST(SkyPlane, AlbedoZeroAndOneStayWithinTheirBounds) {
  for (SamplingMode mode : kModes) {
    const Stats black = render(test::lambertian(0.0f), kGrazing, mode);
    EXPECT_TRUE(black.finite);
    EXPECT_EQ(black.max, 0.0) << modeName(mode);
    const Stats white = render(test::lambertian(1.0f), kGrazing, mode);
    EXPECT_TRUE(white.finite);
    EXPECT_NEAR(white.mean, 1.0, 4.0 * white.error + 0.01) << modeName(mode);  // energy neither gained nor lost
  }
}

TEST(SkyPlane, SmoothWhiteMetalMirrorsTheSkyAndRoughOneNeverGainsEnergy) {
  for (SamplingMode mode : kModes) {
    // Roughness 0 (GGX alpha clamped to 1e-3): a mirror of the sky away from grazing.
    const Stats mirror = render(whiteMetal(0.0f), kModerate, mode);
    ASSERT_TRUE(mirror.finite) << modeName(mode);
    EXPECT_NEAR(mirror.mean, 1.0, 4.0 * mirror.error + 0.01) << modeName(mode);
    // At grazing and at roughness 1 single-scattering microfacets lose energy; they must never gain it.
    for (const auto& [roughness, tilt] : {std::pair{0.0f, kGrazing}, std::pair{1.0f, kGrazing}, std::pair{1.0f, kModerate}}) {
      const Stats st = render(whiteMetal(roughness), tilt, mode);
      ASSERT_TRUE(st.finite) << modeName(mode) << " roughness " << roughness << " tilt " << tilt;
      EXPECT_LE(st.mean, 1.0 + 4.0 * st.error + 1e-3) << modeName(mode) << " roughness " << roughness << " tilt " << tilt;
      EXPECT_GT(st.mean, 0.3) << modeName(mode) << " roughness " << roughness << " tilt " << tilt;
    }
  }
}

TEST(SkyPlane, EveryBudgetAtOneStaysFiniteAndUnbiasedWhereItMustBe) {
  for (SamplingMode mode : kModes) {
    const Stats st = render(test::lambertian(0.5f), kModerate, mode, /*budgetsAtOne=*/true);
    ASSERT_TRUE(st.finite) << modeName(mode);
    // One segment: the sky seen directly by next-event estimation and the BSDF, in every mode.
    EXPECT_NEAR(st.mean, 0.5, 4.0 * st.error + 0.02) << modeName(mode);
  }
}

}  // namespace
}  // namespace vpl
