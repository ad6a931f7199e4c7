// The display pipeline in a headless OSMesa context against the render core's own tonemap: what
// the window shows is the image the PNG writer makes, for any exposure.
#include <cmath>
#include "render/film/image_metrics.h"
#include "render/film/tonemap.h"
#include "render/session/render_job.h"
#include "tests/unit/support.h"
#include "ui/osmesa_capture.h"

namespace vpl {
namespace {

// Largest difference, in 8-bit levels, between the capture and toDisplayByte of every pixel.
int worstLevelDifference(const Image& image, float exposure) {
  const std::vector<uint8_t> shown = ui::captureThroughDisplay(image, exposure);
  EXPECT_EQ(shown.size(), image.pixels.size() * 3);
  int worst = 0;
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(int(shown[3 * i + size_t(c)]) - int(toDisplayByte(image.pixels[i][c], exposure))));
  return worst;
}

TEST(Display, CaptureEqualsTheTonemappedImageAtTwoExposures) {
  // A ramp over four decades in every channel, rows running the other way, so that a flipped or
  // transposed image, a missing exposure or a wrong curve all show.
  Image ramp(97, 61);
  for (int y = 0; y < ramp.height; ++y)
    for (int x = 0; x < ramp.width; ++x)
      ramp.at(x, y) = glm::vec3(1e-3f * std::pow(1e4f, float(x) / float(ramp.width - 1)),
                                1e-3f * std::pow(1e4f, float(y) / float(ramp.height - 1)), float(x + y) / 160.0f);
  for (float exposure : {0.0f, -2.5f, 1.5f}) EXPECT_LE(worstLevelDifference(ramp, exposure), 1) << exposure;

  RenderJobSettings s;
  s.scenePath = test::sourceDir() + "/scenes/cornell_box.gltf";
  s.width = 64;
  s.height = 48;
  s.spp = 4;
  const Image cornell = runRenderJob(s).image;
  for (float exposure : {0.0f, 1.0f}) EXPECT_LE(worstLevelDifference(cornell, exposure), 1) << exposure;
}

TEST(Display, ErrorViewEqualsTheFalseColourOfTheRenderCore) {
  // Relative variances over six decades, and zeros: the shader's ramp is image_metrics' ramp.
  Image errors(120, 9);
  for (int y = 0; y < errors.height; ++y)
    for (int x = 0; x < errors.width; ++x)
      errors.at(x, y) = glm::vec3(y == 0 ? 0.0f : std::pow(10.0f, -5.0f + 6.0f * float(x) / float(errors.width - 1)));
  const std::vector<uint8_t> shown = ui::captureThroughDisplay(errors, 3.0f, ui::DisplayView::ErrorMap);  // exposure ignored
  const Image expected = falseColourLog(errors);
  int worst = 0;
  for (size_t i = 0; i < errors.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(int(shown[3 * i + size_t(c)]) - int(toDisplayByte(expected.pixels[i][c], 0.0f))));
  EXPECT_LE(worst, 2);
}

TEST(Display, OnePixelAndOddSizes) {
  Image one(1, 1);
  one.pixels[0] = glm::vec3(0.25f, 0.5f, 2.0f);
  EXPECT_LE(worstLevelDifference(one, 0.0f), 1);
  Image odd(3, 7);
  for (size_t i = 0; i < odd.pixels.size(); ++i) odd.pixels[i] = glm::vec3(float(i) / 21.0f);
  EXPECT_LE(worstLevelDifference(odd, 0.0f), 1);
}

}  // namespace
}  // namespace vpl
