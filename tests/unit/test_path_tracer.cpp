// The reference path tracer (`brdf`) against analytic answers, and its determinism. Its agreement with
// an independent renderer on whole scenes is test_cycles_anchor.
#include <cmath>
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
  for (int pass = 0; pass < spp; ++pass) {
    if (connectPaths > 0) connections.build(scene, seed, uint64_t(pass), connectPaths, maxDepth - 1, true);
    r.stats += renderer.renderPass(film, uint64_t(pass));
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
          const MeanAndError m = channelMean(r.image, c);
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
      const MeanAndError m = channelMean(r.image, c);
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
    const MeanAndError m = channelMean(some.image, c);
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
