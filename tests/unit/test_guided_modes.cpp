// Every sampling mode converges to the same image: guided modes against BSDF sampling on the
// Cornell box and on the indirect-dominated two-room scene (DESIGN.md §2 step 8).
#include <cmath>
#include "render/film/image_metrics.h"
#include "render/session/render_job.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

RenderJobResult render(const std::string& scene, SamplingMode mode, int spp, uint64_t seed,
                       int guidedVertices = GuideSettings{}.guidedVertices) {
  RenderJobSettings s;
  s.guide.guidedVertices = guidedVertices;
  s.scenePath = test::sourceDir() + "/scenes/" + scene;
  s.mode = mode;
  s.width = 32;
  s.height = 24;
  s.spp = spp;
  s.seed = seed;
  s.tracer.maxDepth = 8;
  s.preview.vpl.count = 4096;
  return runRenderJob(s);
}

// Difference of the two images' means, in units of its standard error (pixels are independent).
double meanDifferenceInSigmas(const Image& a, const Image& b, int channel) {
  double sum = 0.0, sum2 = 0.0;
  const double n = double(a.pixels.size());
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const double d = double(a.pixels[i][channel]) - b.pixels[i][channel];
    sum += d;
    sum2 += d * d;
  }
  const double mean = sum / n, var = std::max(1e-30, sum2 / n - mean * mean);
  return mean / std::sqrt(var / n);
}

struct Case {
  const char* scene;
  SamplingMode mode;
  int guidedVertices = GuideSettings{}.guidedVertices;  // 0: every vertex near a cache point
};

class GuidedModes : public ::testing::TestWithParam<Case> {};

TEST_P(GuidedModes, AgreeWithBsdfSampling) {
  const Case c = GetParam();
  const RenderJobResult reference = render(c.scene, SamplingMode::Brdf, 1024, 1);
  const RenderJobResult guided = render(c.scene, c.mode, 1024, 2, c.guidedVertices);
  EXPECT_GT(guided.guideSamples, 0u) << "the guide was never used";
  EXPECT_EQ(guided.discarded, 0u);
  for (int ch = 0; ch < 3; ++ch) {
    const double z = meanDifferenceInSigmas(guided.image, reference.image, ch);
    EXPECT_LT(std::abs(z), 4.0) << modeName(c.mode) << " on " << c.scene << ", channel " << ch << ": " << z << " sigma";
    std::printf("%s %s channel %d: %.2f sigma\n", c.scene, modeName(c.mode), ch, z);
  }
  std::printf("relative bias %.4f\n", relativeBias(guided.image, reference.image));
  EXPECT_LT(std::abs(relativeBias(guided.image, reference.image)), 0.05);
}

INSTANTIATE_TEST_SUITE_P(Scenes, GuidedModes,
                         ::testing::Values(Case{"cornell_box.gltf", SamplingMode::Mis}, Case{"cornell_box.gltf", SamplingMode::Metropolis},
                                           Case{"cornell_box.gltf", SamplingMode::Mixture}, Case{"two_rooms.gltf", SamplingMode::Mis},
                                           Case{"two_rooms.gltf", SamplingMode::Metropolis}, Case{"two_rooms.gltf", SamplingMode::Mixture},
                                           // Guiding every vertex near a cache point (--guided-vertices 0).
                                           Case{"two_rooms.gltf", SamplingMode::Mis, 0}, Case{"cornell_box.gltf", SamplingMode::Metropolis, 0},
                                           Case{"two_rooms.gltf", SamplingMode::Mixture, 0}),
                         [](const auto& info) {
                           return std::string(info.param.scene[0] == 'c' ? "Cornell" : "TwoRooms") + "_" + modeName(info.param.mode) +
                                  (info.param.guidedVertices == 0 ? "_EveryVertex" : "");
                         });

TEST(GuidedModes, ErrorFallsAsOneOverSpp) {
  // relMSE between two independent renders is twice the variance (against the reference-free mean):
  // for an unbiased, consistent estimator it falls as 1/spp.
  for (SamplingMode mode : {SamplingMode::Mis, SamplingMode::Metropolis, SamplingMode::Mixture}) {
    auto spread = [&](int spp) {
      return relMse(render("two_rooms.gltf", mode, spp, 11).image, render("two_rooms.gltf", mode, spp, 12).image);
    };
    const double e16 = spread(16), e128 = spread(128);
    std::printf("%s relMSE between seeds: 16 spp %.4g, 128 spp %.4g (ratio %.2f, ideal 8)\n", modeName(mode), e16, e128,
                e16 / e128);
    // Chains shared by the pixels of a tile correlate their errors, so allow some slack below 8.
    EXPECT_GT(e16 / e128, 4.0) << modeName(mode);
    EXPECT_LT(e16 / e128, 12.0) << modeName(mode);
  }
}

}  // namespace
}  // namespace vpl
