// An absolute anchor that does not come from this integrator: every unbiased mode (brdf, mis,
// metropolis, mixture) against converged Blender Cycles renders of the built-in scenes that Cycles
// maps exactly (../shared/tools/cycles/README.md: Lambertians and front-side emitters). cornell_glossy
// and the generated interior have dielectric glossy layers (metallic 0 with specularFactor > 0) and
// are refused by the tool; door_ajar maps but is left out: at this test's budget its pixels are
// dominated by rare paths through the slit, so their batch spread is no reliable standard error.
// The references are committed in tests/data/cycles/ with the script that made them
// (make_references.sh): 8 seeds x 16384 spp each, 32x24 pixels, Cycles --max-bounces 7. Cycles
// counts bounces after the camera hit, vplview counts path segments from the camera (1 = direct
// light only), so that is vplview's --max-depth 8 (checked: Cycles 0/1/2 bounces agree with vplview
// depth 1/2/3 within noise on the Cornell box, and with no other depth).
//
// The test is per pixel and channel: z = (vplview - Cycles) / sqrt(se_vplview^2 + se_cycles^2),
// both standard errors from the spread of independent renders (kBatches vplview seeds, each with its
// own VPLs, guide and chains; Cycles' 8 seeds). The statistics and their bounds are derived at
// struct Bounds below.
//
// Known residual (measured, far below this test's noise): with 65536 spp of brdf, vplview is
// 0.00 +- 0.05 % from these references on the Cornell box but 0.2 +- 0.03 % brighter on two_rooms
// (0.1 % with direct light only, growing with depth). With direct light only, most of it sits in
// pixels the lamp lights at grazing angles, and there Cycles 3.4 is the one that is off: for a
// Lambertian point lit by a 1 m square lamp seen 3 to 6 degrees above the lamp's plane (on a wall,
// and on a floor), Cycles (262144 spp) gave 1.6 % and 6.9 % less than the exact polygon irradiance;
// vplview matched it to 0.1 % on the wall (on the floor its shadow rays stopped on the lamp itself:
// a separate vplview bug, reported). Where the rest comes from is not pinned down. 0.2 % is 1.5 of
// this test's standard errors of the image mean on two_rooms, inside its bound of 5.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>
#include "render/film/image_io.h"
#include "render/scene/gltf_loader.h"
#include "render/session/render_job.h"
#include "tests/unit/pixel_agreement.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

constexpr int kWidth = 32, kHeight = 24;
constexpr int kMaxDepth = 8;  // = Cycles --max-bounces 7
constexpr int kCyclesSeeds = 8;

// The bounds, for two unbiased estimates. With kBatches = 16 vplview batches (and Cycles' standard
// error, from 8 seeds, a small part of the sum: its 131072 spp against vplview's few thousand), z is
// close to Student t with about 15 degrees of freedom: E z = 0, E z^2 = 15/13 = 1.15,
// var z^2 = 3.4, P(|z| > 4) = 0.0012, P(|z| > 5) = 1.6e-4.
// - Pixels are independent in brdf, mis and mixture, and nearly so in metropolis (chains are per
//   tile and pass); the three channels of a pixel are strongly correlated, so count 768 independent
//   pixels, not 2304 pixel-channels. Then sd(mean z) <= sqrt(1.15 / 768) = 0.039: |mean z| < 0.25 is
//   more than 6 sd (false alarm < 1e-9); sd(mean z^2) <= sqrt(3.4 / 768) = 0.067: mean z^2 < 1.6 is
//   6.7 sd above 1.15 (the cap at 25 only lowers it).
// - Pixel-channels beyond 4 sigma: about 0.0012 x 768 = 0.9 pixels expected, at most 3 channels each;
//   more than 1 % of 2304 (23 channels, so at least 8 pixels) has probability P(Poisson(0.9) >= 8)
//   ~ 1e-5.
// - Image mean, per channel: |relDiff| < 5 relSe, two-sided P = 1.6e-4 per channel under t with
//   15 dof (the batches' image means are exactly independent).
// So a correct renderer fails this test with probability well under 1e-3 per case. Measured on the
// eight cases: |mean z| <= 0.085, mean z^2 1.07-1.29, beyond 4 sigma 0-0.26 %, image mean within
// 1.5 standard errors. two_rooms' pixels lit only indirectly are skewed (rare bright paths), which
// makes their tails a little heavier than t and their mean z slightly negative; the bounds leave room.
// What they catch (each tried as a scratch edit): Lambert x0.99 fails all 8 cases (mean z -0.8 to
// -1.3, image -0.6 to -3.3 %); guide pdf x1.05 fails the 6 guided ones; a ninth path segment fails
// the 4 two_rooms cases (+1.8 to +3.8 %).
// - Image mean of two_rooms: besides 5 standard errors, 0.3 % for what the two renderers model
//   differently (the known residual above: Cycles 3.4 is 1.6-6.9 % dark where an area lamp lights at
//   grazing emission angles). With stratified samples the image means' standard errors fall to
//   0.05-0.1 %, below that residual. The Cornell box has no such allowance: it agreed to 0.00 +- 0.05 %.
constexpr test::AgreementBounds kBounds{5.0, 1.6, 0.01, 0.25};
constexpr double kTwoRoomsResidual = 0.003;

constexpr int kBatches = 16;

struct Case {
  const char* scene;
  SamplingMode mode;
  int sppPerBatch;  // kBatches x this per pixel in all; chosen for a few seconds per case in Release
};

std::string caseName(const Case& c) {
  std::string s = c.scene;
  return s + "_" + modeName(c.mode);
}
// So that a failing case is named in gtest's summary, not shown as the bytes of its parameter.
void PrintTo(const Case& c, std::ostream* os) {
  *os << caseName(c) << " (" << kBatches << " x " << c.sppPerBatch << " spp)";
}

test::BatchEstimate cyclesReference(const std::string& scene) {
  std::vector<Image> images;
  for (int seed = 1; seed <= kCyclesSeeds; ++seed) {
    const std::string path =
        test::sourceDir() + "/tests/data/cycles/" + scene + "_seed" + std::to_string(seed) + ".exr";
    if (!std::filesystem::exists(path)) {
      ADD_FAILURE() << path << " is missing (committed; remake with tests/data/cycles/make_references.sh)";
      return {};
    }
    images.push_back(readExr(path));
    if (images.back().width != kWidth || images.back().height != kHeight) {
      ADD_FAILURE() << path << " is " << images.back().width << "x" << images.back().height << ", not " << kWidth << "x"
                    << kHeight;
      return {};
    }
  }
  return test::estimateFromBatches(images);
}

test::BatchEstimate renderVplview(const Case& c) {
  const SceneData data = loadGltf(test::sourceDir() + "/scenes/" + c.scene + ".gltf");
  std::vector<Image> images;
  uint64_t discarded = 0, guideSamples = 0;
  for (int b = 0; b < kBatches; ++b) {
    RenderJobSettings s;
    s.scenePath = c.scene;
    s.mode = c.mode;
    s.width = kWidth;
    s.height = kHeight;
    s.spp = c.sppPerBatch;
    s.seed = 7001 + uint64_t(b);
    s.tracer.maxDepth = kMaxDepth;
    const RenderJobResult r = runRenderJob(s, data);
    discarded += r.discarded;
    guideSamples += r.guideSamples;
    images.push_back(r.image);
  }
  EXPECT_EQ(discarded, 0u) << "non-finite or negative samples";
  if (c.mode != SamplingMode::Brdf) EXPECT_GT(guideSamples, 0u) << "the guide was never used";
  return test::estimateFromBatches(images);
}

class CyclesAnchor : public ::testing::TestWithParam<Case> {};

TEST_P(CyclesAnchor, AgreesWithCyclesPixelByPixel) {
  const Case c = GetParam();
  const test::BatchEstimate cycles = cyclesReference(c.scene);
  if (cycles.batches == 0) return;
  const test::Agreement a = test::compareEstimates(renderVplview(c), cycles);
  EXPECT_GT(a.samples, kWidth * kHeight * 3 / 2) << caseName(c) << ": too few noisy pixels to judge";
  test::AgreementBounds bounds = kBounds;
  if (std::string(c.scene) == "two_rooms") bounds.imageFloor = kTwoRoomsResidual;
  test::expectAgreement(a, "[cycles] " + caseName(c), bounds);
}

INSTANTIATE_TEST_SUITE_P(
    ExactlyMappedScenes, CyclesAnchor,
    ::testing::Values(Case{"cornell_box", SamplingMode::Brdf, 256}, Case{"cornell_box", SamplingMode::Mis, 256},
                      Case{"cornell_box", SamplingMode::Metropolis, 256},
                      Case{"cornell_box", SamplingMode::Mixture, 256}, Case{"two_rooms", SamplingMode::Brdf, 192},
                      Case{"two_rooms", SamplingMode::Mis, 192}, Case{"two_rooms", SamplingMode::Metropolis, 192},
                      Case{"two_rooms", SamplingMode::Mixture, 192}),
    [](const auto& info) { return caseName(info.param); });

}  // namespace
}  // namespace vpl
