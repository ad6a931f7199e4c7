// The VPL preview: close to the path-traced image, and sane at the extremes of DESIGN.md §5.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include "render/core/color.h"
#include "render/film/film.h"
#include "render/film/image_metrics.h"
#include "render/session/render_job.h"
#include "render/session/tile_renderer.h"
#include "render/scene/gltf_loader.h"
#include "render/vpl/vpl_preview.h"
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

// The median over pixel-channels of (x - r)^2 / (r^2 + 0.01): the typical pixel's error, which one
// firefly does not move.
double medianRelativeSquaredError(const Image& image, const Image& reference) {
  std::vector<double> e;
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = double(image.pixels[i][c]) - reference.pixels[i][c];
      e.push_back(d * d / (double(reference.pixels[i][c]) * reference.pixels[i][c] + 0.01));
    }
  std::nth_element(e.begin(), e.begin() + std::ptrdiff_t(e.size() / 2), e.end());
  return e[e.size() / 2];
}

// What a user sees first, the preview's first passes, converges to the image that more passes of the
// same VPLs and clusters give: the typical pixel's error against the next 2048 passes falls as 1/n
// (ideal ratio from 16 to 256 passes: 14.3 with the limit's own noise; measured 8.2-11.4; bound 5),
// on every built-in scene. A bias of the early passes stops the fall: lit pixels 10 % darker in the
// first 256 passes gave 2.3-3.8 on three scenes (3 % is not seen: 5.8-9.0). Per-pixel z-scores and the
// relMSE do not work here: a pixel's preview passes are so heavy-tailed (now and then one bright
// cluster) that even 64-pass batches misjudge their variance (two disjoint sets of 1024 passes gave
// mean z^2 up to 1.75), and the relMSE's ratio ranged over 2.7-16 between scenes.
TEST(Preview, FirstPassesConvergeToTheManyPassLimit) {
  for (const std::string scene : {"cornell_box.gltf", "cornell_glossy.gltf", "two_rooms.gltf", "interior.glb"}) {
    const std::string path = scene == "interior.glb" ? std::string(VPLVIEW_BINARY_DIR) + "/scenes/interior.glb"
                                                     : test::sourceDir() + "/scenes/" + scene;
    if (!std::filesystem::exists(path)) {
      std::printf("%s is not built: skipped\n", path.c_str());
      continue;
    }
    const RenderScene rs(loadGltf(path));
    const Camera camera(defaultCamera(rs.data()), 16, 12);
    PreviewSettings ps;
    ps.vpl.count = 4096;
    const VplField field = buildVplField(rs, camera, std::make_shared<VplSet>(traceVpls(rs, ps.vpl)), ps);
    const TileRenderer renderer(camera, 7, previewShader(rs, field, ps));
    Film first(16, 12), limit(16, 12);
    for (uint64_t pass = 256; pass < 256 + 2048; ++pass) renderer.renderPass(limit, pass);
    const Image converged = limit.resolve();
    double after16 = 0.0;
    for (uint64_t pass = 0; pass < 256; ++pass) {
      renderer.renderPass(first, pass);
      if (pass == 15) after16 = medianRelativeSquaredError(first.resolve(), converged);
    }
    const double after256 = medianRelativeSquaredError(first.resolve(), converged);
    std::printf("%s: median error against the next 2048 passes after 16 passes %.4g, after 256 %.4g (ratio %.1f, ideal 14.3)\n",
                scene.c_str(), after16, after256, after16 / after256);
    EXPECT_GT(after16 / after256, 5.0) << scene;
  }
}

// The viewer's first preview (coarsePreviewSettings: few slices, few clusters per pixel) shows the same
// light as the full one: the two images' means agree, after one coarse pass and after many.
TEST(Preview, CoarseFirstPreviewMatchesTheFullOne) {
  for (const std::string scene : {"cornell_box.gltf", "two_rooms.gltf"}) {
    const RenderScene rs(loadGltf(test::sourceDir() + "/scenes/" + scene));
    const Camera camera(defaultCamera(rs.data()), 160, 120);
    PreviewSettings full;
    full.vpl.count = 4096;
    full.slices.maxSliceSize = 64;  // many slices at this small size, as a window has
    const auto vpls = std::make_shared<VplSet>(traceVpls(rs, full.vpl));
    const PreviewSettings coarse = coarsePreviewSettings(full, 160 * 120);
    const VplField fullField = buildVplField(rs, camera, vpls, full), coarseField = buildVplField(rs, camera, vpls, coarse);
    EXPECT_LE(coarseField.tree.slices.size(), size_t(2 * CoarsePreview{}.slices)) << scene;  // median splits: up to 2x
    EXPECT_LT(coarseField.tree.slices.size(), fullField.tree.slices.size()) << scene;
    const TileRenderer fullRenderer(camera, 3, previewShader(rs, fullField, full));
    const TileRenderer coarseRenderer(camera, 3, previewShader(rs, coarseField, coarse));
    Film fullFilm(160, 120), coarseFilm(160, 120);
    for (uint64_t pass = 0; pass < 64; ++pass) fullRenderer.renderPass(fullFilm, pass);
    coarseRenderer.renderPass(coarseFilm, 0);
    const Image onePass = coarseFilm.resolve();
    for (uint64_t pass = 1; pass < 64; ++pass) coarseRenderer.renderPass(coarseFilm, pass);
    const double first = relativeBias(onePass, fullFilm.resolve()), many = relativeBias(coarseFilm.resolve(), fullFilm.resolve());
    std::printf("%s: coarse preview against the full one (64 passes): mean %+.4f after 1 pass, %+.4f after 64\n", scene.c_str(),
                first, many);
    EXPECT_TRUE(allFinite(onePass)) << scene;
    EXPECT_LT(std::abs(first), 0.10) << scene;
    EXPECT_LT(std::abs(many), 0.03) << scene;
  }
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
