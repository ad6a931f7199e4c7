// Every guided mode converges to the image of BSDF sampling (DESIGN.md §2 step 8), pixel by pixel,
// on every built-in scene; so does the VPL-driven roulette and splitting (weight_window.h). Each side is a set of independent batches (distinct seeds: new VPLs, new
// guide, new chains), so the per-pixel standard errors include everything that varies with the seed.
// `brdf` itself is anchored to Cycles (test_cycles_anchor) and to analytic cases (furnace, sky plane,
// light types), so a bug shared with next-event estimation or roulette does not cancel here.
#include <cmath>
#include <filesystem>
#include "render/film/image_metrics.h"
#include "render/scene/gltf_loader.h"
#include "render/session/render_job.h"
#include "tests/unit/pixel_agreement.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

constexpr int kWidth = 16, kHeight = 12, kMaxDepth = 8;
// Few pixels with many samples each: a per-pixel bias stands out of less noise.
constexpr int kBatches = 16, kSpp = 256;

RenderJobSettings settings(const std::string& scene, SamplingMode mode, int spp, uint64_t seed,
                           int guidedVertices = GuideSettings{}.guidedVertices,
                           RouletteRule roulette = RouletteRule::Sqrt, int connectPaths = -1) {
  RenderJobSettings s;
  s.scenePath = test::builtInScene(scene);
  s.mode = mode;
  s.width = kWidth;
  s.height = kHeight;
  s.spp = spp;
  s.seed = seed;
  s.tracer.maxDepth = kMaxDepth;
  s.preview.vpl.count = 4096;
  s.guide.guidedVertices = guidedVertices;
  s.tracer.roulette = roulette;
  // VPL connections as the mode has them by default (on in the guided modes), with fewer light
  // paths than the default's floor of 1024: at 16x12 pixels those would cost more than the pixels.
  s.connections.paths = connectPaths >= 0 ? connectPaths : isGuided(mode) ? 64 : 0;
  return s;
}

// `batches` renders of `spp` each, seeds firstSeed, firstSeed + 1, ...; the scene is read once.
test::BatchEstimate renderBatches(const SceneData& data, const RenderJobSettings& base, int batches, uint64_t firstSeed,
                                  uint64_t* guideSamples = nullptr, uint64_t* discarded = nullptr,
                                  uint64_t* branches = nullptr, int* windowed = nullptr, int* learned = nullptr,
                                  int* guidesLearned = nullptr, int* joinDepthsChosen = nullptr) {
  std::vector<Image> images;
  for (int b = 0; b < batches; ++b) {
    RenderJobSettings s = base;
    s.seed = firstSeed + uint64_t(b);
    const RenderJobResult r = runRenderJob(s, data);
    if (guideSamples) *guideSamples += r.guideSamples;
    if (discarded) *discarded += r.discarded;
    if (branches) *branches += r.branches;
    if (windowed && r.windowFromPass > 0) ++*windowed;
    if (learned && r.learnedBsdfProbability >= 0.0) ++*learned;
    if (guidesLearned && r.learnedGuideShare > 0.0) ++*guidesLearned;
    if (joinDepthsChosen && r.joinDepthChosen) ++*joinDepthsChosen;
    images.push_back(r.image);
  }
  return test::estimateFromBatches(images);
}

struct Case {
  const char* scene;
  SamplingMode mode;
  int guidedVertices = GuideSettings{}.guidedVertices;  // 0: every vertex near a cache point
  RouletteRule roulette = RouletteRule::Sqrt;  // brdf, the reference, always uses it
  // mis as shipped (each cache point's BSDF probability learned), with Hua & Low's Markov chain for the
  // guide's directions, or with their fixed BSDF probability of 0.5.
  enum class Mis { Default, Chain, Fixed } mis = Mis::Default;
  int connectPaths = -1;  // VPL connections' light paths per pass; -1: the mode's default (settings())
  // The guide learned from the paths with the VPLs as prior (the default), the VPL guide alone (the
  // paper's), or learned alone.
  enum class Guide { Learned, Vpl, LearnedOnly } guide = Guide::Learned;
  int joinDepth = -1;  // the deepest camera vertex that joins (ConnectionSettings::joinDepth); -1: every vertex, -2: auto
};

std::string caseName(const Case& c) {
  std::string scene = c.scene;
  scene = scene.substr(0, scene.find('.'));
  return scene + "_" + modeName(c.mode) + (c.guidedVertices == 0 ? "_every_vertex" : "") +
         (c.roulette == RouletteRule::Vpl ? "_vpl_roulette" : c.roulette == RouletteRule::Auto ? "_auto_roulette" : "") +
         (c.mis == Case::Mis::Chain ? "_chain" : c.mis == Case::Mis::Fixed ? "_fixed_probability" : "") +
         (c.connectPaths == 0 ? "_no_connections" : c.connectPaths > 0 ? "_connections" : "") +
         (c.guide == Case::Guide::Vpl ? "_vpl_guide" : c.guide == Case::Guide::LearnedOnly ? "_learned_only_guide" : "") +
         (c.joinDepth >= 0 ? "_join_depth_" + std::to_string(c.joinDepth) : "") +
         (c.joinDepth == ConnectionSettings::kJoinDepthAuto ? "_join_depth_auto" : "");
}

class GuidedModes : public ::testing::TestWithParam<Case> {};

TEST_P(GuidedModes, AgreeWithBsdfSamplingPixelByPixel) {
  const Case c = GetParam();
  const std::string path = test::builtInScene(c.scene);
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is not built (target interior_scene)";
  const SceneData data = loadGltf(path);
  const test::BatchEstimate reference =
      renderBatches(data, settings(c.scene, SamplingMode::Brdf, kSpp, 0), kBatches, 1000);
  uint64_t guideSamples = 0, discarded = 0, branches = 0;
  int windowed = 0, learned = 0, guidesLearned = 0, joinDepthsChosen = 0;
  RenderJobSettings s = settings(c.scene, c.mode, kSpp, 0, c.guidedVertices, c.roulette, c.connectPaths);
  s.guide.misChain = c.mis == Case::Mis::Chain;
  if (c.mis == Case::Mis::Fixed) s.guide.learnSelection = false;
  s.guide.learnDirections = c.guide != Case::Guide::Vpl;
  s.guide.vplPrior = c.guide != Case::Guide::LearnedOnly;
  s.connections.joinDepth = c.joinDepth;
  const test::BatchEstimate guided = renderBatches(data, s, kBatches, 2000, &guideSamples, &discarded, &branches,
                                                   &windowed, &learned, &guidesLearned, &joinDepthsChosen);
  if (c.joinDepth == ConnectionSettings::kJoinDepthAuto)
    EXPECT_EQ(joinDepthsChosen, kBatches) << "the join depth trial did not decide";
  if (c.mode == SamplingMode::Mis && s.guide.learnSelection)
    EXPECT_EQ(learned, kBatches) << "no cache point learned its probability";
  if (c.guide != Case::Guide::Vpl && c.mode != SamplingMode::Brdf)
    EXPECT_EQ(guidesLearned, kBatches) << "no guide learned from the paths";
  if (c.mode != SamplingMode::Brdf) EXPECT_GT(guideSamples, 0u) << "the guide was never used";
  if (c.roulette == RouletteRule::Vpl || c.roulette == RouletteRule::Auto) EXPECT_GT(branches, 0u) << "no path was ever split";
  if (c.roulette == RouletteRule::Auto) EXPECT_EQ(windowed, kBatches) << "the auto rule did not switch to the window";
  EXPECT_EQ(discarded, 0u);
  // Sampling glossy lobes from the guide alone (metropolis, mixture) leaves rare, large weights: at
  // 65536 spp one pixel of cornell_glossy still moved from 35 % below brdf to 50 % above it. brdf's own
  // batches there have rare large samples too (light reflected by the glossy walls onto the matte
  // ones): one pixel of its 16 batches sat 8 standard errors below both mis and mis with the chain.
  // Since vertex 1's direction joined vertex 0's (pixel_sampler.h) the regular noise is lower and those
  // samples weigh more: over six sets of brdf seeds mis's mean z^2 is 1.20-1.84 (1.33-1.55 before),
  // its mean z the same (+0.22 on average both ways, within the bound). Every mode there gets the
  // heavy-tail bounds.
  const bool heavyTails = std::string(c.scene) == "cornell_glossy.gltf";
  test::expectAgreement(test::compareEstimates(guided, reference), caseName(c) + " against brdf",
                        heavyTails ? test::kHeavyTailBounds : test::AgreementBounds{});
}

INSTANTIATE_TEST_SUITE_P(
    BuiltInScenes, GuidedModes,
    ::testing::Values(Case{"cornell_box.gltf", SamplingMode::Mis}, Case{"cornell_box.gltf", SamplingMode::Metropolis},
                      Case{"cornell_box.gltf", SamplingMode::Mixture}, Case{"cornell_glossy.gltf", SamplingMode::Mis},
                      Case{"cornell_glossy.gltf", SamplingMode::Metropolis}, Case{"cornell_glossy.gltf", SamplingMode::Mixture},
                      Case{"two_rooms.gltf", SamplingMode::Mis}, Case{"two_rooms.gltf", SamplingMode::Metropolis},
                      Case{"two_rooms.gltf", SamplingMode::Mixture}, Case{"interior.glb", SamplingMode::Mis},  // the 157K-triangle hall: one mode, for CI time
                      // Guiding every vertex near a cache point (--guided-vertices 0).
                      Case{"two_rooms.gltf", SamplingMode::Mis, 0}, Case{"cornell_glossy.gltf", SamplingMode::Metropolis, 0},
                      Case{"two_rooms.gltf", SamplingMode::Mixture, 0},
                      // Roulette and splitting by the VPLs' estimate.
                      Case{"cornell_box.gltf", SamplingMode::Brdf, 1, RouletteRule::Vpl},
                      Case{"two_rooms.gltf", SamplingMode::Mis, 1, RouletteRule::Vpl},
                      Case{"cornell_glossy.gltf", SamplingMode::Metropolis, 0, RouletteRule::Vpl},
                      Case{"door_ajar.gltf", SamplingMode::Brdf, 1, RouletteRule::Auto},
                      // mis with the paper's Markov chain, and with its fixed BSDF probability.
                      Case{"two_rooms.gltf", SamplingMode::Mis, 1, RouletteRule::Sqrt, Case::Mis::Chain},
                      Case{"cornell_glossy.gltf", SamplingMode::Mis, 1, RouletteRule::Sqrt, Case::Mis::Chain},
                      Case{"two_rooms.gltf", SamplingMode::Mis, 1, RouletteRule::Sqrt, Case::Mis::Fixed},
                      Case{"cornell_glossy.gltf", SamplingMode::Mis, 0, RouletteRule::Sqrt, Case::Mis::Fixed},
                      // VPL connections: off in a guided mode (the paper's setting), on in brdf.
                      Case{"two_rooms.gltf", SamplingMode::Mis, 1, RouletteRule::Sqrt, Case::Mis::Default, 0},
                      Case{"door_ajar.gltf", SamplingMode::Brdf, 1, RouletteRule::Sqrt, Case::Mis::Default, 128},
                      Case{"cornell_glossy.gltf", SamplingMode::Brdf, 1, RouletteRule::Vpl, Case::Mis::Default, 128},
                      // The VPL guide alone (the paper's), and guides learned alone; learned from the
                      // VPLs' everywhere else.
                      Case{"two_rooms.gltf", SamplingMode::Mis, 1, RouletteRule::Sqrt, Case::Mis::Default, -1, Case::Guide::Vpl},
                      Case{"door_ajar.gltf", SamplingMode::Mixture},
                      Case{"cornell_glossy.gltf", SamplingMode::Metropolis, 1, RouletteRule::Sqrt, Case::Mis::Default, -1,
                           Case::Guide::LearnedOnly},
                      // Joins from the first vertex only: the weights of both sides leave the deeper joins out.
                      Case{"door_ajar.gltf", SamplingMode::Mis, 1, RouletteRule::Sqrt, Case::Mis::Default, -1,
                           Case::Guide::Learned, 0},
                      // The join depth tried pass by pass, then the one that measured best.
                      Case{"cornell_box.gltf", SamplingMode::Mis, 1, RouletteRule::Sqrt, Case::Mis::Default, -1,
                           Case::Guide::Learned, ConnectionSettings::kJoinDepthAuto}),
    [](const auto& info) { return caseName(info.param); });

// The statistic is not blind: BSDF sampling against itself passes, and against itself 5 % brighter
// in a tenth of the pixels, or 3 % brighter in alternate rows and darker in the others by as much
// (which leaves the image mean unchanged), it fails.
TEST(PixelAgreement, SeesABiasInSomePixelsOrOneThatCancelsOut) {
  const SceneData data = loadGltf(test::builtInScene("cornell_box.gltf"));
  const RenderJobSettings s = settings("cornell_box.gltf", SamplingMode::Brdf, kSpp, 0);
  std::vector<Image> a, b;
  for (int i = 0; i < kBatches; ++i) {
    RenderJobSettings si = s;
    si.seed = 3000 + uint64_t(i);
    a.push_back(runRenderJob(si, data).image);
    si.seed = 4000 + uint64_t(i);
    b.push_back(runRenderJob(si, data).image);
  }
  const test::BatchEstimate reference = test::estimateFromBatches(b);
  test::expectAgreement(test::compareEstimates(test::estimateFromBatches(a), reference), "brdf against brdf");

  auto biased = [&](auto scaleOfPixel) {
    std::vector<Image> images = a;
    for (Image& image : images)
      for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] *= scaleOfPixel(i);
    return test::compareEstimates(test::estimateFromBatches(images), reference);
  };
  const test::Agreement tenth = biased([](size_t i) { return i % 10 == 0 ? 1.05f : 1.0f; });
  // 3 % brighter in even rows, and the odd rows darker by what makes each channel's image mean
  // exactly what it was: the image mean cannot see this bias however small its noise.
  glm::dvec3 evenRows(0.0), oddRows(0.0);
  for (size_t i = 0; i < reference.mean.size(); ++i) ((i / size_t(kWidth)) % 2 == 0 ? evenRows : oddRows) += reference.mean[i];
  const glm::vec3 oddScale = glm::vec3(1.0 - 0.03 * evenRows / oddRows);
  const test::Agreement halves = biased([&](size_t i) { return (i / size_t(kWidth)) % 2 == 0 ? glm::vec3(1.03f) : oddScale; });
  std::printf("5 %% in a tenth of the pixels: mean z^2 %.3f, beyond 4 sigma %.2f %%\n", tenth.meanZ2, 100 * tenth.beyond4);
  std::printf("+3 %% in even rows, about -3 %% in odd rows: image |z| %.2f, mean z^2 %.3f\n", halves.imageZ, halves.meanZ2);
  EXPECT_TRUE(tenth.meanZ2 >= 1.6 || tenth.beyond4 >= 0.02) << "a 5 % bias in a tenth of the pixels went unseen";
  EXPECT_GE(halves.meanZ2, 1.6) << "a bias that cancels across rows went unseen";
  EXPECT_LT(halves.imageZ, 5.0);  // and the image mean alone would not have seen it
}

// A consistency check, not a bias check (the per-pixel tests above are): the spread between two seeds
// falls as 1/spp. Chains shared by the pixels of a tile correlate their errors, so allow some slack
// below the ideal ratio of 8. With the joins' learned choice of light vertices the later passes are
// better than the first ones, so the spread may fall faster (measured: uniform 7.0-9.6, learned
// 6.8-12.6), up to 20.
TEST(GuidedModes, SpreadBetweenSeedsFallsAsOneOverSpp) {
  const SceneData data = loadGltf(test::builtInScene("two_rooms.gltf"));
  for (const bool learnChoice : {false, true}) {
    for (SamplingMode mode : {SamplingMode::Mis, SamplingMode::Metropolis, SamplingMode::Mixture}) {
      auto spread = [&](int spp) {
        RenderJobSettings a = settings("two_rooms.gltf", mode, spp, 11), b = settings("two_rooms.gltf", mode, spp, 12);
        a.connections.learnChoice = b.connections.learnChoice = learnChoice;
        return relMse(runRenderJob(a, data).image, runRenderJob(b, data).image);
      };
      const double e16 = spread(16), e128 = spread(128);
      std::printf("%s, %s joins: relMSE between seeds: 16 spp %.4g, 128 spp %.4g (ratio %.2f, ideal 8)\n", modeName(mode),
                  learnChoice ? "learned" : "uniform", e16, e128, e16 / e128);
      EXPECT_GT(e16 / e128, 4.0) << modeName(mode);
      EXPECT_LT(e16 / e128, learnChoice ? 20.0 : 12.0) << modeName(mode);
    }
  }
}

}  // namespace
}  // namespace vpl
