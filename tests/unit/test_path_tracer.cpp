// The reference path tracer (`brdf`) against analytic answers, and its determinism. Its agreement with
// an independent renderer on whole scenes is test_cycles_anchor.
#include <cmath>
#include <numbers>
#include <cstdio>
#include <string>
#include <tuple>
#include <tbb/global_control.h>
#include "render/film/film.h"
#include "render/integrator/light_vertex_cache.h"
#include "render/integrator/path_tracer.h"
#include "render/scene/camera.h"
#include "render/scene/gltf_loader.h"
#include "render/session/tile_renderer.h"
#include "render/vpl/irradiance_grid.h"
#include "tests/unit/scene_builders.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

struct Rendered {
  Image image;
  PassStats stats;
  std::vector<glm::dvec3> passMeans;  // each pass's image mean
};

// connectPaths > 0: VPL connections to that many light paths per pass.
Rendered renderScene(const RenderScene& scene, int width, int height, int spp, uint64_t seed, int maxDepth = 64,
                     RouletteRule roulette = PathTracerSettings{}.roulette, int rrStart = PathTracerSettings{}.rrStartDepth,
                     int connectPaths = 0, int joinsPerVertex = 1, float joinRoulette = 0.0f, int joinDepth = -1) {
  const Camera camera(defaultCamera(scene.data()), width, height);
  PathTracerSettings settings;
  settings.maxDepth = maxDepth;
  settings.roulette = roulette;
  settings.rrStartDepth = rrStart;
  IrradianceGrid irradiance;
  if (roulette == RouletteRule::Vpl) irradiance = IrradianceGrid(scene, 1 << 16, seed, maxDepth);
  LightVertexCache connections(
      ConnectionSettings{.joinsPerVertex = joinsPerVertex, .joinDepth = joinDepth, .shadowRoulette = joinRoulette});
  const PathTracer tracer(scene, settings, &irradiance, connectPaths > 0 ? &connections : nullptr);
  const TileRenderer renderer(camera, seed, pathTracerShader(tracer));
  Film film(width, height);
  Rendered r;
  glm::dvec3 sumBefore(0.0);  // of the passes so far, over the pixels' means
  for (int pass = 0; pass < spp; ++pass) {
    if (connectPaths > 0) connections.build(scene, seed, uint64_t(pass), connectPaths, maxDepth - 1, true);
    r.stats += renderer.renderPass(film, uint64_t(pass));
    glm::dvec3 mean(0.0);
    for (const glm::vec3& p : film.resolve().pixels) mean += glm::dvec3(p);
    mean *= double(pass + 1) / double(width * height);
    r.passMeans.push_back(mean - sumBefore);
    sumBefore = mean;
  }
  r.image = film.resolve();
  return r;
}

// Per-channel image mean and the standard error of that mean, treating pixels as independent.
struct MeanAndError {
  double mean, error;
};
MeanAndError channelMean(const Image& image, int channel) {
  double sum = 0, sum2 = 0;
  const size_t n = image.pixels.size();
  for (const glm::vec3& p : image.pixels) {
    sum += p[channel];
    sum2 += double(p[channel]) * p[channel];
  }
  const double mean = sum / n;
  return {mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n)};
}

// The same where joins are made: every pixel of a pass joins the same light vertices, so pixels are
// not independent and their spread understates the error (the furnace's z-scores then spread over
// +-5 across seeds). Passes are independent but for each pixel's stratified camera numbers, which only
// make their means vary less, so the larger of the pixels' and the passes' errors is a safe one.
MeanAndError channelMeanOverPasses(const Rendered& r, int channel) {
  MeanAndError m = channelMean(r.image, channel);
  const size_t n = r.passMeans.size();
  double sum = 0.0, sum2 = 0.0;
  for (const glm::dvec3& p : r.passMeans) sum += p[channel], sum2 += p[channel] * p[channel];
  const double mean = sum / double(n), variance = std::max(0.0, sum2 / double(n) - mean * mean) / double(n - 1);
  m.error = std::max(m.error, std::sqrt(variance));
  return m;
}

// Albedo, Russian roulette rule and the depth it starts at: every rule must keep the estimate unbiased.
class WhiteFurnace : public ::testing::TestWithParam<std::tuple<float, RouletteRule, int>> {};

TEST_P(WhiteFurnace, ConvergesToAnalyticRadiance) {
  const auto [rho, roulette, rrStart] = GetParam();
  const float le = 0.5f;
  const RenderScene scene(test::furnaceScene(rho, le));
  const Rendered r = renderScene(scene, 32, 32, 64, 11, 1024, roulette, rrStart);
  const double expected = le / (1.0 - rho);
  for (int c = 0; c < 3; ++c) {
    const MeanAndError m = channelMean(r.image, c);
    EXPECT_NEAR(m.mean, expected, 4.0 * m.error + 1e-3 * expected) << "rho " << rho << " channel " << c;
  }
  EXPECT_EQ(r.stats.discarded, 0u);
}

std::string furnaceName(const ::testing::TestParamInfo<WhiteFurnace::ParamType>& info) {
  const float rho = std::get<0>(info.param);
  const RouletteRule rule = std::get<1>(info.param);
  return "albedo" + std::to_string(int(rho * 10)) +
         (rule == RouletteRule::Sqrt ? "_sqrt" : rule == RouletteRule::Vpl ? "_vpl" : "_throughput") +
         "_from" + std::to_string(std::get<2>(info.param));
}

INSTANTIATE_TEST_SUITE_P(AlbedosAndRoulette, WhiteFurnace,
                         ::testing::Combine(::testing::Values(0.0f, 0.5f, 0.8f),
                                            ::testing::Values(RouletteRule::Throughput, RouletteRule::Sqrt, RouletteRule::Vpl),
                                            ::testing::Values(1, 5)),
                         furnaceName);

// VPL connections: every path is made by BSDF sampling, next-event estimation and the joins at each
// vertex, and the MIS weights of all of them must sum to 1, or the furnace's answer moves (with 3
// joins a vertex, the joins' count is 3 times as large on both sides). Depth 3 also checks that no
// join makes a path longer than the limit (the answer is then the series' first four terms).
TEST(WhiteFurnace, ConvergesWithVplConnections) {
  const float le = 0.5f;
  for (const int joins : {1, 3}) {
    for (const float rho : {0.5f, 0.8f}) {
      for (const int depth : {3, 1024}) {
        const RenderScene scene(test::furnaceScene(rho, le));
        const Rendered r = renderScene(scene, 32, 32, 64, 11, depth, RouletteRule::Sqrt, 5, 512, joins);
        const double expected = depth == 3 ? le * (1.0 + rho + rho * rho + rho * rho * rho) : le / (1.0 - rho);
        for (int c = 0; c < 3; ++c) {
          const MeanAndError m = channelMeanOverPasses(r, c);
          EXPECT_NEAR(m.mean, expected, 4.0 * m.error + 1e-3 * expected)
              << "joins " << joins << " rho " << rho << " depth " << depth << " channel " << c;
        }
        EXPECT_EQ(r.stats.discarded, 0u);
      }
    }
  }
}

// Joins from the first vertices only (ConnectionSettings::joinDepth): both sides' weights must leave
// out exactly the joins the limit forbids (a light side that still counted them made door_ajar 32 to
// 48 % too dark). Fewer joins trace fewer rays.
TEST(WhiteFurnace, ConvergesWithJoinsOnlyAtTheFirstVertices) {
  const float le = 0.5f, rho = 0.8f;
  const RenderScene scene(test::furnaceScene(rho, le));
  const Rendered every = renderScene(scene, 32, 32, 64, 11, 1024, RouletteRule::Sqrt, 5, 512, 2);
  const double expected = le / (1.0 - rho);
  for (const int joinDepth : {0, 1, 2}) {
    const Rendered r = renderScene(scene, 32, 32, 64, 11, 1024, RouletteRule::Sqrt, 5, 512, 2, 0.0f, joinDepth);
    for (int c = 0; c < 3; ++c) {
      const MeanAndError m = channelMeanOverPasses(r, c);
      EXPECT_NEAR(m.mean, expected, 4.0 * m.error + 1e-3 * expected) << "join depth " << joinDepth << " channel " << c;
    }
    EXPECT_EQ(r.stats.discarded, 0u);
    EXPECT_LT(double(r.stats.rays), 0.9 * double(every.stats.rays)) << "join depth " << joinDepth;
  }
}

// Roulette on the joins' shadow rays: a share of 4 sends nearly every join through it (each is worth
// less than 4 times what its sample holds), so a survivor that forgot to weigh 1/survival, or a
// survival drawn from the number it is tested with, moves the answer. The rays it saves are counted.
TEST(WhiteFurnace, ConvergesWithRouletteOnTheJoinsShadowRays) {
  const float le = 0.5f, rho = 0.8f;
  const RenderScene scene(test::furnaceScene(rho, le));
  const Rendered all = renderScene(scene, 32, 32, 64, 11, 1024, RouletteRule::Sqrt, 5, 512, 2);
  const Rendered some = renderScene(scene, 32, 32, 64, 11, 1024, RouletteRule::Sqrt, 5, 512, 2, 4.0f);
  const double expected = le / (1.0 - rho);
  for (int c = 0; c < 3; ++c) {
    const MeanAndError m = channelMeanOverPasses(some, c);
    EXPECT_NEAR(m.mean, expected, 4.0 * m.error + 1e-3 * expected) << "channel " << c;
  }
  EXPECT_EQ(some.stats.discarded, 0u);
  EXPECT_LT(double(some.stats.rays), 0.9 * double(all.stats.rays)) << "the roulette traced nearly every join";
}

TEST(WhiteFurnace, GlossyMetalNeverGainsEnergy) {
  // A perfect-white rough metal reflects at most what it receives: radiance <= le / (1 - 1) is
  // unbounded, so bound it by the path length instead: L <= le * (depth + 1).
  SceneData s = test::furnaceScene(1.0f, 0.5f);
  s.materials[0].metallic = 1.0f;
  s.materials[0].roughness = 0.4f;
  s.materials[0].specularFactor = 1.0f;
  const int depth = 8;
  const RenderScene scene(std::move(s));
  const Rendered r = renderScene(scene, 16, 16, 32, 3, depth);
  const MeanAndError m = channelMean(r.image, 1);
  EXPECT_LE(m.mean, 0.5 * (depth + 1) + 4.0 * m.error);
  EXPECT_GT(m.mean, 0.5);  // it does reflect something
}

// Direct light from a globe lamp of 528 small triangles onto a Lambertian ceiling 0.15 m above its top,
// through the whole path tracer (next-event estimation, emitter hits of BSDF rays, their MIS
// weights, the shadow rays ending short of the lamp): a patch of the ceiling a millimetre wide has
// radiance albedo / pi x Lambert's formula over the globe's facets that face it. Shadow rays
// parallel to the light sample's direction from the offset origin ended on the lamp's facets seen at
// grazing angles, for a fifth of the samples: 3.7 % too dark (2.9 % with the globe 0.6 m below).
TEST(PathTracer, DirectLightFromAGlobeMatchesLambertsFormula) {
  SceneData s;
  s.materials.push_back(test::lambertian(0.5f));
  Material lamp;
  lamp.baseColor = glm::vec3(0.0f);
  lamp.emission = glm::vec3(3.0f, 2.0f, 1.0f);
  lamp.doubleSided = false;
  s.materials.push_back(lamp);
  MeshData plane;
  plane.positions = {{0.0f, 2.8f, -2.0f}, {4.0f, 2.8f, -2.0f}, {4.0f, 2.8f, 2.0f}, {0.0f, 2.8f, 2.0f}};
  plane.indices = {0, 1, 2, 0, 2, 3};  // its normal faces down
  plane.material = 0;
  s.meshes.push_back(plane);
  const MeshData globe = test::globe(glm::dvec3(2.0, 2.5, -0.3), 0.15, 12, 24, 1);
  s.meshes.push_back(globe);
  s.boundsMin = glm::vec3(0.0f, 2.0f, -2.0f);
  s.boundsMax = glm::vec3(4.0f, 2.8f, 2.0f);
  const glm::dvec3 p(2.3, 2.8, -0.2), down(0.0, -1.0, 0.0);
  CameraData camera;
  camera.eye = glm::vec3(p + glm::dvec3(0.6, -0.5, 0.3));
  camera.target = glm::vec3(p);
  camera.yfov = 1e-3f;
  s.camera = camera;
  const RenderScene scene(s);
  const Rendered r = renderScene(scene, 4, 4, 65536, 17, 3);
  const double irradiance = test::convexMeshIrradiance(globe, p, down);
  for (int c = 0; c < 3; ++c) {
    const double expected = 0.5 / std::numbers::pi * double(lamp.emission[c]) * irradiance;
    const MeanAndError m = channelMean(r.image, c);
    EXPECT_NEAR(m.mean, expected, 4.0 * m.error + 1e-6 * expected) << "channel " << c;
    EXPECT_LT(m.error / expected, 1.5e-3) << "too noisy to see a 1 % error";
    std::printf("globe on a ceiling, channel %d: %+.3f %% from Lambert's formula (standard error %.3f %%)\n", c,
                (m.mean / expected - 1.0) * 100.0, m.error / expected * 100.0);
  }
}

// `--join-depth auto` measures depth 1 on passes that join at every vertex (JoinDepthCounterfactual):
// the second estimate must be exactly what a pass joining up to depth 1 makes from the same numbers,
// the rays it leaves out exactly those that pass does not trace, and the sample itself untouched.
TEST(PathTracer, CounterfactualJoinDepthIsThatDepthsOwnPass) {
  const RenderScene scene(test::furnaceScene(0.8f, 0.5f));
  const Camera camera(defaultCamera(scene.data()), 24, 20);
  PathTracerSettings settings;
  settings.roulette = RouletteRule::Sqrt;
  LightVertexCache connections(ConnectionSettings{.joinsPerVertex = 2});
  const PathTracer tracer(scene, settings, nullptr, &connections);
  const TileRenderer renderer(camera, 3, pathTracerShader(tracer));
  for (uint64_t pass : {0u, 5u}) {
    connections.build(scene, 3, pass, 300, settings.maxDepth - 1, true);
    Film plain(24, 20), every(24, 20), counterfactual(24, 20), one(24, 20);
    connections.setJoinDepth(-1);
    const PassStats plainStats = renderer.renderPass(plain, pass);
    const PassStats everyStats = renderer.renderPass(every, pass, nullptr, &counterfactual, 1);
    connections.setJoinDepth(1);
    const PassStats oneStats = renderer.renderPass(one, pass);
    const Image a = plain.resolve(), b = every.resolve(), c = counterfactual.resolve(), d = one.resolve();
    for (size_t i = 0; i < a.pixels.size(); ++i) {
      ASSERT_EQ(a.pixels[i], b.pixels[i]) << "pass " << pass << " pixel " << i << ": the sample itself changed";
      ASSERT_EQ(c.pixels[i], d.pixels[i]) << "pass " << pass << " pixel " << i;
    }
    EXPECT_EQ(plainStats.rays, everyStats.rays);
    EXPECT_EQ(plainStats.raysPastCounterfactual, 0u);
    EXPECT_GT(everyStats.raysPastCounterfactual, everyStats.rays / 10);
    EXPECT_EQ(everyStats.rays - everyStats.raysPastCounterfactual, oneStats.rays) << "pass " << pass;
    // A pass that already stops at depth 1 has no counterfactual to weigh: its own samples stand in.
    Film own(24, 20), standIn(24, 20);
    const PassStats limited = renderer.renderPass(own, pass, nullptr, &standIn, 1);
    EXPECT_EQ(limited.raysPastCounterfactual, 0u);
    const Image e = own.resolve(), f = standIn.resolve();
    for (size_t i = 0; i < e.pixels.size(); ++i) ASSERT_EQ(e.pixels[i], f.pixels[i]) << "pixel " << i;
  }
}

TEST(PathTracer, SameSeedSameImageForAnyThreadCount) {
  const RenderScene scene(test::furnaceScene(0.7f, 1.0f));
  for (const int connectPaths : {0, 700}) {  // with VPL connections, the light vertices too
    Image one, two;
    {
      tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
      one = renderScene(scene, 24, 20, 4, 5, 64, PathTracerSettings{}.roulette, 5, connectPaths).image;
    }
    {
      tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
      two = renderScene(scene, 24, 20, 4, 5, 64, PathTracerSettings{}.roulette, 5, connectPaths).image;
    }
    ASSERT_EQ(one.pixels.size(), two.pixels.size());
    for (size_t i = 0; i < one.pixels.size(); ++i) ASSERT_EQ(one.pixels[i], two.pixels[i]) << "pixel " << i << " paths " << connectPaths;
  }
}

}  // namespace
}  // namespace vpl
