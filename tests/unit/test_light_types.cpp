// Every light type against a value computed here in closed form, not by this renderer: a Lambertian
// floor (y = 0, albedo rho, no specular lobe) seen from above, lit by one light at a time. A single
// plane cannot light itself, so the image is direct light only, in every mode and at any depth:
//
//   point  (KHR_lights_punctual, candela I at height h):   L = rho/pi * I * h / d^3
//   spot   (same, times glTF's angular attenuation):       L = rho/pi * I * att(cos) * h / d^3,
//          att = clamp((cos - cos_outer) / (cos_inner - cos_outer), 0, 1)^2 (the spec's reference
//          curve); full intensity inside the inner cone ("spot light intensity refers to the
//          brightness inside the innerConeAngle"), 0 outside the outer one
//   directional (lux E, travelling at theta from the normal): L = rho/pi * E * cos(theta)
//   emissive square (radiance Le, parallel, facing down):   L = rho * Le * F, F the point-to-parallel-
//          rectangle form factor (corner formula, summed with signs over the four corner rectangles)
//   uniform sky (radiance Ls per channel):                  L = rho * Ls
//
// The glTF units are used as they are: the loader keeps candela and lux as the light's intensity (no
// 4 pi anywhere), and radiance is in the same unit per steradian.
//
// Each pixel's expected value is the analytic radiance averaged over the pixel (16 x 16 points of a
// pinhole camera written here; the film's box filter averages samples uniform over the pixel square).
// Two kinds of check:
//  - punctual lights: next-event estimation of one delta light is deterministic at a given point, so a
//    pixel's only randomness is where its samples land. The mean of spp samples of a quantity whose
//    range over the pixel is R has a standard deviation of at most R / (2 sqrt(spp)) (Popoviciu), so
//    every pixel must lie within 5 of those bounds plus 0.2 % of its value (float rounding): no
//    estimate of the noise is needed and no pixel may be off.
//  - area light and sky (Monte Carlo): two renders with different seeds give, per pixel, the mean and
//    an unbiased estimate of its variance, (a - b)^2 / 4. Per 8 x 8 block of pixels and over the whole
//    image the summed error must stay within 5 (block) / 4.5 (image) estimated standard errors plus
//    0.2 % / 0.1 % of the value: a block is ~64 pixels, so the studentised sum is close to normal and
//    5 sigma is a false alarm of about 1e-5 per block.
// The narrow spots (1 degree, and 0.1 degree where float cosines hold only ~25 ulps of 1 - cos) are
// checked at their centre, the case where a floor on (cos_inner - cos_outer) would dim them.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>
#include "render/session/render_job.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr float kFloorHalf = 6.0f;
const glm::dvec3 kRho(0.7, 0.5, 0.3);  // floor albedo per channel; lights are white unless stated

// ---- The camera, written out here: a pinhole, image (0, 0) at the top-left corner ------------------
struct View {
  glm::dvec3 eye, target, up;
  double yfov;
  int width = 32, height = 32;

  CameraData camera() const {
    CameraData c;
    c.eye = glm::vec3(eye);
    c.target = glm::vec3(target);
    c.up = glm::vec3(up);
    c.yfov = float(yfov);
    return c;
  }
  // Where the ray through image position (px, py) meets the floor y = 0.
  glm::dvec3 floorPoint(double px, double py) const {
    const glm::dvec3 f = glm::normalize(target - eye);
    const glm::dvec3 r = glm::normalize(glm::cross(f, up));
    const glm::dvec3 u = glm::cross(r, f);
    const double ty = std::tan(0.5 * yfov), tx = ty * width / height;
    const glm::dvec3 d = f + (2.0 * px / width - 1.0) * tx * r + (1.0 - 2.0 * py / height) * ty * u;
    return eye + d * (-eye.y / d.y);
  }
};

// Looking straight down from height `height` onto the floor around (cx, cz).
View downView(double height, double yfov, double cx = 0.0, double cz = 0.0) {
  return {glm::dvec3(cx, height, cz), glm::dvec3(cx, 0.0, cz), glm::dvec3(0, 0, -1), yfov};
}

// Irradiance / pi at floor point x (so that the radiance is rho times it): the analytic answer.
using Truth = std::function<double(const glm::dvec3& x)>;

struct Expected {
  std::vector<double> mean;   // pixel average of the truth (times rho per channel at comparison)
  std::vector<double> range;  // max - min of the truth over the pixel
  double peak = 0.0;
};

Expected expectedImage(const View& v, const Truth& truth) {
  constexpr int kSub = 16;
  Expected e;
  for (int y = 0; y < v.height; ++y)
    for (int x = 0; x < v.width; ++x) {
      double sum = 0.0, lo = INFINITY, hi = -INFINITY;
      for (int j = 0; j <= kSub; ++j)
        for (int i = 0; i <= kSub; ++i) {
          // Nodes (including the pixel's edges) for the range; cell midpoints for the mean.
          const double node = truth(v.floorPoint(x + double(i) / kSub, y + double(j) / kSub));
          lo = std::min(lo, node);
          hi = std::max(hi, node);
          if (i < kSub && j < kSub) sum += truth(v.floorPoint(x + (i + 0.5) / kSub, y + (j + 0.5) / kSub));
        }
      e.mean.push_back(sum / (kSub * kSub));
      e.range.push_back(hi - lo);
      e.peak = std::max(e.peak, hi);
    }
  return e;
}

// ---- Scenes -------------------------------------------------------------------------------------
Material lambert(const glm::vec3& rho) {
  Material m;
  m.baseColor = rho;
  m.metallic = 0.0f;
  m.roughness = 1.0f;
  m.specularFactor = 0.0f;  // no specular lobe: f = rho / pi exactly
  return m;
}

SceneData floorScene(const View& view) {
  SceneData s;
  s.materials.push_back(lambert(glm::vec3(kRho)));
  MeshData floor;
  floor.name = "floor";
  const float h = kFloorHalf;
  floor.positions = {{-h, 0, -h}, {h, 0, -h}, {h, 0, h}, {-h, 0, h}};
  floor.indices = {0, 2, 1, 0, 3, 2};  // normal +y
  s.meshes.push_back(floor);
  s.boundsMin = glm::vec3(-h, 0.0f, -h);
  s.boundsMax = glm::vec3(h, 2.0f, h);
  s.camera = view.camera();
  return s;
}

// glTF's reference spot curve, from the spec (double precision, exact cosines).
double spotAttenuation(double cosAxis, double innerAngle, double outerAngle) {
  const double ci = std::cos(innerAngle), co = std::cos(outerAngle);
  const double t = std::clamp((cosAxis - co) / (ci - co), 0.0, 1.0);
  return t * t;
}

// Irradiance / pi from a punctual light of intensity I at p on the floor point x, attenuation `att`.
double punctual(const glm::dvec3& p, double intensity, const glm::dvec3& x, double att = 1.0) {
  const glm::dvec3 d = p - x;
  const double dist = glm::length(d);
  return intensity * att * (d.y / dist) / (dist * dist) / kPiD;
}

// Form factor from a point to the rectangle [0, X] x [0, Z] in a parallel plane at distance c, one
// corner straight above the point (Howell's catalogue, C-11); odd in X and in Z, so signed corner
// rectangles add up to any parallel rectangle.
double cornerFormFactor(double X, double Z, double c) {
  const double a = X / c, b = Z / c;
  const double sa = std::sqrt(1.0 + a * a), sb = std::sqrt(1.0 + b * b);
  return (a / sa * std::atan(b / sa) + b / sb * std::atan(a / sb)) / (2.0 * kPiD);
}
double rectangleFormFactor(const glm::dvec3& x, double x0, double x1, double z0, double z1, double height) {
  const double c = height - x.y;
  return cornerFormFactor(x1 - x.x, z1 - x.z, c) - cornerFormFactor(x0 - x.x, z1 - x.z, c) -
         cornerFormFactor(x1 - x.x, z0 - x.z, c) + cornerFormFactor(x0 - x.x, z0 - x.z, c);
}

// ---- Rendering and checks -----------------------------------------------------------------------
RenderJobResult render(const SceneData& scene, const View& view, SamplingMode mode, int spp, uint64_t seed,
                       const SkySettings& sky = {}) {
  RenderJobSettings s;
  s.scenePath = "light types (in memory)";
  s.mode = mode;
  s.width = view.width;
  s.height = view.height;
  s.spp = spp;
  s.seed = seed;
  s.tracer.maxDepth = 3;
  s.preview.vpl.count = 1024;
  s.sky = sky;
  // A Markov chain serves all pixels of a tile in a pass, so metropolis's pixels are correlated, the
  // more so as its target is peaked; the error model here counts pixels as independent. The VPL guide
  // keeps the chain mixing; learned guides of this scene are all lamp (a floor under a lamp and
  // nothing else) and its uniform proposals stick. Metropolis with learned guides is held to brdf by
  // GuidedModes, whose error model counts independent seeds.
  s.guide.learnDirections = mode != SamplingMode::Metropolis;
  const RenderJobResult r = runRenderJob(s, scene);
  EXPECT_EQ(r.discarded, 0u) << modeName(mode);
  return r;
}

const SamplingMode kModes[] = {SamplingMode::Brdf, SamplingMode::Mis, SamplingMode::Preview};

// Punctual lights: every pixel within the jitter bound (see the header), and the image sum within 5
// of its own bound plus 0.1 %. `include` (optional) restricts the check to some pixels.
// `scale` is the per-channel factor of the truth: the floor albedo times the light's colour.
void expectPunctualImage(const RenderJobResult& r, const Expected& e, int spp, const std::string& what,
                         const std::function<bool(int)>& include = nullptr, const glm::dvec3& scale = kRho) {
  ASSERT_EQ(r.image.pixels.size(), e.mean.size());
  const double sqrtN = std::sqrt(double(spp));
  int bad = 0, checked = 0, lit = 0;
  double worst = 0.0;
  std::string worstText;
  for (int k = 0; k < 3; ++k) {
    double sumErr = 0.0, sumVal = 0.0, var = 0.0;
    for (size_t p = 0; p < e.mean.size(); ++p) {
      if (include && !include(int(p))) continue;
      const double a = scale[k] * e.mean[p], range = scale[k] * e.range[p];
      const double got = r.image.pixels[p][k];
      const double bound = range / (2.0 * sqrtN);
      const double tol = 5.0 * bound + 2e-3 * a + 1e-6 * scale[k] * e.peak;
      const double err = got - a;
      ++checked;
      lit += a > 0.01 * scale[k] * e.peak;
      if (std::abs(err) > tol) {
        ++bad;
        if (std::abs(err) / tol > worst) {
          worst = std::abs(err) / tol;
          worstText = "pixel (" + std::to_string(p % size_t(r.image.width)) + ", " + std::to_string(p / size_t(r.image.width)) + ") channel " + std::to_string(k) +
                      ": expected " + std::to_string(a) + " got " + std::to_string(got) + " tolerance " + std::to_string(tol);
        }
      }
      sumErr += err;
      sumVal += a;
      var += bound * bound;
    }
    EXPECT_LE(std::abs(sumErr), 5.0 * std::sqrt(var) + 1e-3 * sumVal)
        << what << " channel " << k << ": image sum " << sumVal + sumErr << " expected " << sumVal;
  }
  EXPECT_EQ(bad, 0) << what << ": " << bad << " of " << checked << " pixel values off; worst " << worstText;
  EXPECT_GT(lit, 0) << what << ": nothing lit, the check would be vacuous";
}

// Monte Carlo lights: two seeds, per 8 x 8 block and whole-image sums against estimated standard errors.
void expectStatisticalImage(const RenderJobResult& a, const RenderJobResult& b, const Expected& e, const std::string& what,
                            double maxRelativeError, const glm::dvec3& scale = kRho) {
  const int w = a.image.width, h = a.image.height;
  ASSERT_EQ(a.image.pixels.size(), e.mean.size());
  for (int k = 0; k < 3; ++k) {
    double totErr = 0.0, totVal = 0.0, totVar = 0.0;
    for (int by = 0; by < h; by += 8)
      for (int bx = 0; bx < w; bx += 8) {
        double err = 0.0, val = 0.0, var = 0.0;
        for (int y = by; y < std::min(h, by + 8); ++y)
          for (int x = bx; x < std::min(w, bx + 8); ++x) {
            const size_t p = size_t(y) * size_t(w) + size_t(x);
            const double m = 0.5 * (double(a.image.pixels[p][k]) + b.image.pixels[p][k]);
            const double d = double(a.image.pixels[p][k]) - b.image.pixels[p][k];
            err += m - scale[k] * e.mean[p];
            val += scale[k] * e.mean[p];
            var += 0.25 * d * d;
          }
        EXPECT_LE(std::abs(err), 5.0 * std::sqrt(var) + 2e-3 * val + 1e-6 * scale[k] * e.peak)
            << what << " channel " << k << " block (" << bx / 8 << ", " << by / 8 << "): sum " << val + err << " expected "
            << val << " standard error " << std::sqrt(var);
        totErr += err;
        totVal += val;
        totVar += var;
      }
    EXPECT_LE(std::abs(totErr), 4.5 * std::sqrt(totVar) + 1e-3 * totVal)
        << what << " channel " << k << ": image sum " << totVal + totErr << " expected " << totVal << " standard error "
        << std::sqrt(totVar);
    // The test must be able to see an error of a few percent: its own tolerance has to be smaller.
    EXPECT_LT(4.5 * std::sqrt(totVar) / totVal, maxRelativeError) << what << " channel " << k << ": too noisy to judge";
    if (k == 1)
      std::printf("%-32s image mean %.5f expected %.5f (relative %+.4f, standard error %.4f)\n", what.c_str(),
                  (totVal + totErr) / (w * h), totVal / (w * h), totErr / totVal, std::sqrt(totVar) / totVal);
  }
}

// ---- Punctual lights ----------------------------------------------------------------------------
TEST(LightTypes, PointLightFollowsInverseSquareAndCosine) {
  const View view = downView(3.0, 1.2);
  const glm::dvec3 p(0.3, 1.0, -0.2);
  const double intensity = 4.0;
  SceneData scene = floorScene(view);
  PunctualLight light;
  light.type = LightType::Point;
  light.position = glm::vec3(p);
  light.intensity = glm::vec3(float(intensity));
  scene.lights.push_back(light);
  const Expected e = expectedImage(view, [&](const glm::dvec3& x) { return punctual(p, intensity, x); });
  for (SamplingMode mode : kModes)
    expectPunctualImage(render(scene, view, mode, 64, 1), e, 64, std::string("point, ") + modeName(mode));
}

TEST(LightTypes, ColouredPointLightScalesEachChannel) {
  const View view = downView(3.0, 1.2);
  const glm::dvec3 p(-0.4, 0.8, 0.1);
  const glm::dvec3 colour(0.2, 1.0, 3.0);
  SceneData scene = floorScene(view);
  PunctualLight light;
  light.type = LightType::Point;
  light.position = glm::vec3(p);
  light.intensity = glm::vec3(colour) * 2.0f;
  scene.lights.push_back(light);
  // Each channel: the floor albedo times the light colour.
  const Expected e = expectedImage(view, [&](const glm::dvec3& x) { return punctual(p, 2.0, x); });
  expectPunctualImage(render(scene, view, SamplingMode::Brdf, 64, 2), e, 64, "coloured point", nullptr, kRho * colour);
}

PunctualLight spotLight(const glm::dvec3& p, const glm::dvec3& dir, double intensity, double inner, double outer) {
  PunctualLight light;
  light.type = LightType::Spot;
  light.position = glm::vec3(p);
  light.direction = glm::vec3(dir);
  light.intensity = glm::vec3(float(intensity));
  light.cosInner = float(std::cos(inner));
  light.cosOuter = float(std::cos(outer));
  return light;
}

TEST(LightTypes, SpotLightIsPointInsideInnerConeZeroOutsideOuterAndGltfCurveBetween) {
  const View view = downView(3.0, 1.2);
  const glm::dvec3 p(0.2, 1.5, 0.0);
  const glm::dvec3 dir = glm::normalize(glm::dvec3(0.3, -1.0, 0.2));
  const double intensity = 6.0, inner = 0.35, outer = 0.6;
  SceneData scene = floorScene(view);
  scene.lights.push_back(spotLight(p, dir, intensity, inner, outer));
  auto truth = [&](const glm::dvec3& x) {
    return punctual(p, intensity, x, spotAttenuation(glm::dot(dir, glm::normalize(x - p)), inner, outer));
  };
  const Expected e = expectedImage(view, truth);
  // The image must hold all three regions: full, falloff and dark pixels.
  int full = 0, dark = 0, between = 0;
  for (int y = 0; y < view.height; ++y)
    for (int x = 0; x < view.width; ++x) {
      const glm::dvec3 c = view.floorPoint(x + 0.5, y + 0.5);
      const double cosAxis = glm::dot(dir, glm::normalize(c - p));
      full += cosAxis > std::cos(inner);
      dark += cosAxis < std::cos(outer);
      between += cosAxis <= std::cos(inner) && cosAxis >= std::cos(outer);
    }
  ASSERT_GT(full, 20);
  ASSERT_GT(dark, 20);
  ASSERT_GT(between, 20);
  for (SamplingMode mode : kModes)
    expectPunctualImage(render(scene, view, mode, 64, 3), e, 64, std::string("spot, ") + modeName(mode));
}

// A narrow spot pointing straight down from height 1: at the centre, the point light's value. A floor
// of 1e-3 on cos_inner - cos_outer (glTF's reference code has one) would leave a 1-degree spot at
// (1 - cos 1deg) / 1e-3 squared, 2 % of its intensity.
void narrowSpot(double innerDegrees, double outerDegrees, double cameraHeight, double halfField) {
  const double inner = innerDegrees * kPiD / 180.0, outer = outerDegrees * kPiD / 180.0;
  const View view = downView(cameraHeight, 2.0 * std::atan(halfField / cameraHeight));
  const glm::dvec3 p(0.0, 1.0, 0.0), dir(0.0, -1.0, 0.0);
  const double intensity = 2.0;
  SceneData scene = floorScene(view);
  scene.lights.push_back(spotLight(p, dir, intensity, inner, outer));
  const Expected e = expectedImage(view, [&](const glm::dvec3& x) {
    return punctual(p, intensity, x, spotAttenuation(glm::dot(dir, glm::normalize(x - p)), inner, outer));
  });
  // Float cosines of sub-degree cones are quantised (1 - cos 0.1deg is ~26 float steps below 1, and
  // 1 - cos 0.05deg ~6), so only pixels wholly inside half the inner angle (full intensity, a margin
  // of 4 float steps of the cosine) or beyond 1.25 x the outer one (dark) are compared; the falloff
  // ring in between is the float curve's business.
  auto include = [&](int p) {
    const int x = p % view.width, y = p / view.width;
    double lo = INFINITY, hi = 0.0;
    for (double cx : {0.0, 1.0})
      for (double cy : {0.0, 1.0}) {
        const glm::dvec3 c = view.floorPoint(x + cx, y + cy);
        const double r = std::hypot(c.x, c.z);
        lo = std::min(lo, r);
        hi = std::max(hi, r);
      }
    return hi < std::tan(0.5 * inner) || lo > std::tan(1.25 * outer);
  };
  int centre = 0;
  for (int i = 0; i < view.width * view.height; ++i) {
    const glm::dvec3 c = view.floorPoint(i % view.width + 0.5, i / view.width + 0.5);
    centre += include(i) && std::hypot(c.x, c.z) < std::tan(inner);
  }
  ASSERT_GT(centre, 3) << "the view must hold pixels inside the inner cone";
  for (SamplingMode mode : kModes)
    expectPunctualImage(render(scene, view, mode, 16, 4), e, 16,
                        "spot " + std::to_string(outerDegrees) + " deg, " + modeName(mode), include);
}

TEST(LightTypes, NarrowSpotCentreHasTheFullIntensity) {
  narrowSpot(0.5, 1.0, 0.5, 0.025);  // a 1-degree stage spot
  narrowSpot(0.05, 0.1, 0.2, 0.0025);  // 0.1 degree
}

TEST(LightTypes, DirectionalLightIsIlluminanceTimesCosine) {
  const View view = downView(3.0, 1.2);
  for (double thetaDegrees : {0.0, 50.0, 80.0}) {
    const double theta = thetaDegrees * kPiD / 180.0, lux = 3.0;
    SceneData scene = floorScene(view);
    PunctualLight light;
    light.type = LightType::Directional;
    light.direction = glm::vec3(glm::normalize(glm::dvec3(std::sin(theta), -std::cos(theta), 0.0)));
    light.intensity = glm::vec3(float(lux));
    scene.lights.push_back(light);
    const Expected e = expectedImage(view, [&](const glm::dvec3&) { return lux * std::cos(theta) / kPiD; });
    for (SamplingMode mode : kModes)
      expectPunctualImage(render(scene, view, mode, 16, 5), e, 16,
                          "directional " + std::to_string(int(thetaDegrees)) + " deg, " + modeName(mode));
  }
}

// ---- Area light and sky (Monte Carlo) ------------------------------------------------------------
void emissiveSquareOverFloor(const glm::vec3& offset);

TEST(LightTypes, EmissiveSquareGivesTheRectangleFormFactor) {
  // The form factor itself, against a direct numerical integral of cos cos / (pi r^2) over the square.
  {
    const glm::dvec3 x(0.3, 0.0, -0.1);
    double sum = 0.0;
    const int n = 400;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const glm::dvec3 q(-0.5 + (i + 0.5) / n, 1.0, -0.5 + (j + 0.5) / n);
        const glm::dvec3 d = q - x;
        const double r2 = glm::dot(d, d), c = d.y / std::sqrt(r2);
        sum += c * c / (kPiD * r2) / (double(n) * n);
      }
    ASSERT_NEAR(rectangleFormFactor(x, -0.5, 0.5, -0.5, 0.5, 1.0), sum, 1e-6);
    ASSERT_NEAR(4.0 * cornerFormFactor(1e6, 1e6, 1.0), 1.0, 1e-5);  // an infinite plane
  }

  emissiveSquareOverFloor(glm::vec3(0.0f));
}

// The same scene 50 m from the origin: the shadow rays' origin offsets grow with the coordinates
// (7.6e-4 m here), and a shadow ray that stopped short by a margin relative to the light distance
// alone (1e-4 m) ended on the lamp itself: the floor came out black.
TEST(LightTypes, EmissiveSquareFarFromTheOriginGivesTheSameFormFactor) { emissiveSquareOverFloor(glm::vec3(0.0f, 50.0f, 0.0f)); }

// A 1 m square lamp of radiance 5 at height 1 over the floor, the whole scene moved by `offset`.
void emissiveSquareOverFloor(const glm::vec3& offset) {
  const View view = downView(0.9, 1.6);  // below the square, so it never hides the floor
  const double a = 0.5, height = 1.0, le = 5.0;
  SceneData scene = floorScene(view);
  Material emitter = lambert(glm::vec3(0.0f));  // black: it reflects nothing back
  emitter.emission = glm::vec3(float(le));
  scene.materials.push_back(emitter);
  MeshData square;
  square.name = "emitter";
  const float af = float(a), hf = float(height);
  square.positions = {{-af, hf, -af}, {af, hf, -af}, {af, hf, af}, {-af, hf, af}};
  square.indices = {0, 1, 2, 0, 2, 3};  // normal -y: emits down, single-sided
  square.material = 1;
  scene.meshes.push_back(square);
  const Expected e = expectedImage(view, [&](const glm::dvec3& x) { return le * rectangleFormFactor(x, -a, a, -a, a, height); });
  for (MeshData& m : scene.meshes)
    for (glm::vec3& p : m.positions) p += offset;
  scene.camera->eye += offset;
  scene.camera->target += offset;
  scene.boundsMin += offset;
  scene.boundsMax += offset;
  for (SamplingMode mode : {SamplingMode::Brdf, SamplingMode::Mis, SamplingMode::Metropolis, SamplingMode::Preview}) {
    const RenderJobResult r1 = render(scene, view, mode, 64, 11), r2 = render(scene, view, mode, 64, 12);
    expectStatisticalImage(r1, r2, e, std::string("emissive square, ") + modeName(mode), 0.02);
  }
}

TEST(LightTypes, ColouredSkyGivesAlbedoTimesSkyPerChannel) {
  const View view = downView(3.0, 1.2);
  SceneData scene = floorScene(view);
  SkySettings sky;
  sky.explicitSky = true;
  sky.radiance = glm::vec3(1.0f, 0.6f, 0.3f);
  const Expected e = expectedImage(view, [](const glm::dvec3&) { return 1.0; });
  for (SamplingMode mode : kModes) {
    const RenderJobResult r1 = render(scene, view, mode, 128, 21, sky), r2 = render(scene, view, mode, 128, 22, sky);
    expectStatisticalImage(r1, r2, e, std::string("coloured sky, ") + modeName(mode), 0.02, kRho * glm::dvec3(sky.radiance));
  }
}

// ---- The same through the glTF loader ------------------------------------------------------------
// A .gltf with the floor, a spot light and a camera, both looking down by a node rotation of -90
// degrees about x (glTF lights and cameras point along local -z): checks the loader's units (radians,
// candela x colour), the light's direction and position from the node, and the camera.
TEST(LightTypes, SpotLightFromGltfFileMatchesTheAnalyticImage) {
  const char* gltf = R"({
  "asset": {"version": "2.0"},
  "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_specular"],
  "extensions": {"KHR_lights_punctual": {"lights": [
    {"type": "spot", "color": [1.0, 0.5, 0.25], "intensity": 8.0, "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.5}}]}},
  "scene": 0,
  "scenes": [{"nodes": [0, 1, 2]}],
  "nodes": [
    {"mesh": 0},
    {"camera": 0, "translation": [0.0, 3.0, 0.0], "rotation": [-0.70710678, 0.0, 0.0, 0.70710678]},
    {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0.25, 1.2, -0.1], "rotation": [-0.70710678, 0.0, 0.0, 0.70710678]}],
  "cameras": [{"type": "perspective", "perspective": {"yfov": 1.2, "znear": 0.01}}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.5, 0.3, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0},
                 "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}}],
  "buffers": [{"byteLength": 60, "uri": "data:application/octet-stream;base64,AADAwAAAAAAAAMDAAADAQAAAAAAAAMDAAADAQAAAAAAAAMBAAADAwAAAAAAAAMBAAAACAAEAAAADAAIA"}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-6.0, 0.0, -6.0], "max": [6.0, 0.0, 6.0]},
    {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}]
})";
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "vplview_test_light_types_spot.gltf";
  {
    std::ofstream out(path);
    out << gltf;
  }
  const View view = downView(3.0, 1.2);
  const glm::dvec3 p(0.25, 1.2, -0.1), dir(0.0, -1.0, 0.0), colour(1.0, 0.5, 0.25);
  const Expected e = expectedImage(view, [&](const glm::dvec3& x) {
    return punctual(p, 8.0, x, spotAttenuation(glm::dot(dir, glm::normalize(x - p)), 0.3, 0.5));
  });
  for (SamplingMode mode : {SamplingMode::Brdf, SamplingMode::Preview}) {
    RenderJobSettings s;
    s.scenePath = path.string();
    s.mode = mode;
    s.width = view.width;
    s.height = view.height;
    s.spp = 64;
    s.tracer.maxDepth = 3;
    s.preview.vpl.count = 1024;
    const RenderJobResult r = runRenderJob(s);
    EXPECT_EQ(r.discarded, 0u);
    expectPunctualImage(r, e, 64, std::string("spot from glTF, ") + modeName(mode), nullptr, kRho * colour);
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace vpl
