// The film's accumulation (render/film/film.h): another film's samples added at weight 1 are the
// same as adding them here, and at weight w each counts w times a sample of its own, in the mean and
// in the variance's moments alike (`--join-depth auto` adds its trial passes so, at weight 1).
#include <gtest/gtest.h>
#include "render/film/crossfade.h"
#include "render/film/film.h"

namespace vpl {
namespace {

TEST(Film, AddingAFilmAtWeightOneEqualsAddingItsSamples) {
  Film direct(2, 1), merged(2, 1), other(2, 1);
  for (float v : {0.25f, 3.0f, 1.5f}) {
    direct.addSample(0, 0, glm::vec3(v, 2.0f * v, 0.5f));
    merged.addSample(0, 0, glm::vec3(v, 2.0f * v, 0.5f));
  }
  for (float v : {7.0f, 0.125f}) {
    direct.addSample(0, 0, glm::vec3(v));
    other.addSample(0, 0, glm::vec3(v));
  }
  merged.add(other);
  EXPECT_EQ(direct.resolve().pixels[0], merged.resolve().pixels[0]);
  EXPECT_EQ(direct.resolveVariance().pixels[0], merged.resolveVariance().pixels[0]);
  EXPECT_EQ(direct.sampleRelativeVariance(), merged.sampleRelativeVariance());
  EXPECT_EQ(direct.totalSamples(), 5u);
  EXPECT_EQ(merged.totalSamples(), 5u);
  EXPECT_EQ(merged.resolve().pixels[1], glm::vec3(0.0f));  // no samples: black
}

TEST(Film, AFilmAddedAtAWeightCountsThatManyTimesInTheMean) {
  Film image(1, 1), pass(1, 1);
  image.addSample(0, 0, glm::vec3(1.0f));
  image.addSample(0, 0, glm::vec3(3.0f));
  pass.addSample(0, 0, glm::vec3(10.0f, 20.0f, 30.0f));
  image.add(pass, 0.5);
  // (1 + 3 + 0.5 x 10) / (1 + 1 + 0.5), per channel.
  const glm::vec3 mean = image.resolve().pixels[0];
  EXPECT_NEAR(mean.x, 9.0 / 2.5, 1e-6);
  EXPECT_NEAR(mean.y, 14.0 / 2.5, 1e-6);
  EXPECT_NEAR(mean.z, 19.0 / 2.5, 1e-6);
  EXPECT_EQ(image.totalSamples(), 3u);  // the count of samples, whatever they weigh

  // Weighted moments: grey samples 1, 3 (weight 1) and 10 (weight 0.5): mean 3.6, E[l^2] = 60 / 2.5 = 24,
  // sample variance (24 - 3.6^2) x 3/2, relative to the mean squared.
  Film grey(1, 1), greyPass(1, 1);
  grey.addSample(0, 0, glm::vec3(1.0f));
  grey.addSample(0, 0, glm::vec3(3.0f));
  greyPass.addSample(0, 0, glm::vec3(10.0f));
  grey.add(greyPass, 0.5);
  EXPECT_NEAR(grey.sampleRelativeVariance(), (24.0 - 3.6 * 3.6) * 1.5 / (3.6 * 3.6), 1e-5);

  // A weight of 0 leaves the mean as it was.
  Film zero(1, 1);
  zero.addSample(0, 0, glm::vec3(2.0f));
  zero.add(pass, 0.0);
  EXPECT_EQ(zero.resolve().pixels[0], glm::vec3(2.0f));
}

}  // namespace
TEST(Crossfade, MixesInProportionAndEndsAtTheTargetExactly) {
  Image from(2, 1), to(2, 1);
  from.pixels = {glm::vec3(1.0f, 2.0f, 0.0f), glm::vec3(4.0f)};
  to.pixels = {glm::vec3(3.0f, 0.0f, 0.5f), glm::vec3(0.1f)};
  const Image quarter = crossfade(from, to, 0.25f);
  EXPECT_FLOAT_EQ(quarter.pixels[0].x, 1.5f);
  EXPECT_FLOAT_EQ(quarter.pixels[0].y, 1.5f);
  EXPECT_FLOAT_EQ(quarter.pixels[1].z, 3.025f);
  EXPECT_EQ(crossfade(from, to, 0.0f).pixels, from.pixels);
  EXPECT_EQ(crossfade(from, to, 1.0f).pixels, to.pixels);
  EXPECT_EQ(crossfade(from, to, 7.0f).pixels, to.pixels);  // past the hand-over
  EXPECT_EQ(crossfade(Image(), to, 0.5f).pixels, to.pixels);  // nothing to fade from
}

}  // namespace vpl
