// The VPL preview: close to the path-traced image, and sane at the extremes of DESIGN.md §5.
#include <cmath>
#include "render/core/color.h"
#include "render/film/image_metrics.h"
#include "render/session/render_job.h"
#include "render/vpl/vpl_tracer.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

RenderJobSettings settings(const std::string& scene, SamplingMode mode, int spp) {
  RenderJobSettings s;
  s.scenePath = test::sourceDir() + "/scenes/" + scene;
  s.mode = mode;
  s.width = 48;
  s.height = 36;
  s.spp = spp;
  s.preview.vpl.count = 8192;
  return s;
}

bool allFinite(const Image& image) {
  for (const glm::vec3& p : image.pixels)
    if (!isFiniteNonNegative(p)) return false;
  return true;
}

TEST(Preview, CornellMeanIsCloseToThePathTracer) {
  const RenderJobResult reference = runRenderJob(settings("cornell_box.gltf", SamplingMode::Brdf, 256));
  const RenderJobResult preview = runRenderJob(settings("cornell_box.gltf", SamplingMode::Preview, 16));
  const double bias = relativeBias(preview.image, reference.image);
  std::printf("preview vs brdf on the Cornell box: relative bias of the mean %.4f\n", bias);
  // The clamped geometry term removes some energy near corners; VPL noise adds some spread.
  EXPECT_LT(std::abs(bias), 0.10);
  EXPECT_TRUE(allFinite(preview.image));
  EXPECT_GT(preview.vplCount, 0u);
  EXPECT_GT(preview.sliceCount, 0u);
}

TEST(Preview, ZeroVplsIsDirectLightOnly) {
  RenderJobSettings s = settings("cornell_box.gltf", SamplingMode::Preview, 4);
  s.preview.vpl.count = 0;
  const RenderJobResult none = runRenderJob(s);
  s.preview.vpl.count = 8192;
  const RenderJobResult some = runRenderJob(s);
  EXPECT_EQ(none.vplCount, 0u);
  EXPECT_TRUE(allFinite(none.image));
  EXPECT_LT(meanRgb(none.image).y, meanRgb(some.image).y);  // indirect light adds energy
  EXPECT_GT(meanRgb(none.image).y, 0.0);
}

TEST(Preview, OneVplAndBudgetOneStayFinite) {
  RenderJobSettings s = settings("two_rooms.gltf", SamplingMode::Preview, 4);
  s.preview.vpl.count = 1;
  EXPECT_TRUE(allFinite(runRenderJob(s).image));
  s.preview.vpl.count = 4096;
  test::setPreviewBudgetsToOne(s);
  const RenderJobResult r = runRenderJob(s);
  EXPECT_TRUE(allFinite(r.image));
  EXPECT_DOUBLE_EQ(r.clustersPerSlice, 1.0);
}

TEST(Preview, NoLightAtAllIsBlack) {
  VPL_REQUIRE_SHARED_SCENE(path, "Triangle/glTF/Triangle.gltf");
  RenderJobSettings s = settings("cornell_box.gltf", SamplingMode::Preview, 2);
  s.scenePath = path;
  s.sky.explicitSky = true;
  s.sky.radiance = glm::vec3(0.0f);
  const RenderJobResult r = runRenderJob(s);
  EXPECT_EQ(r.vplCount, 0u);
  EXPECT_EQ(meanRgb(r.image), glm::dvec3(0.0));
}

TEST(Preview, VplOnTheReceiverIsBoundedByTheClamp) {
  Vpl light;
  light.position = glm::vec3(0.0f);
  light.normal = glm::vec3(0, 1, 0);
  light.incident = glm::vec3(0, 1, 0);
  light.flux = glm::vec3(1.0f);
  BsdfParams p;
  p.diffuse = glm::vec3(1.0f);
  p.f0 = glm::vec3(0.0f);
  p.f90 = 0.0f;
  light.bsdf = Bsdf(p, Frame::fromNormal(light.normal));
  const Bsdf receiver(p, Frame::fromNormal(glm::vec3(0, 1, 0)));
  const float minDistance = 0.01f;
  // Exactly on it: nothing (no direction); ever closer: never above flux f f / minDistance^2.
  EXPECT_EQ(vplContribution(light, glm::vec3(0.0f), receiver, glm::vec3(0, 1, 0), minDistance), glm::vec3(0.0f));
  const float bound = 1.0f / (3.14159265f * 3.14159265f) / (minDistance * minDistance);
  for (float d : {1.0f, 1e-2f, 1e-4f, 1e-8f, 1e-20f}) {
    const glm::vec3 c = vplContribution(light, glm::vec3(d, 1e-3f * d, 0.0f), receiver, glm::vec3(0, 1, 0), minDistance);
    EXPECT_TRUE(isFiniteNonNegative(c)) << d;
    EXPECT_LE(c.x, bound * 1.0001f) << d;
  }
}

}  // namespace
}  // namespace vpl
