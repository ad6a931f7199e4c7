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

constexpr int kStructureWidth = 160, kStructureHeight = 120;

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

// The preview sums the paths that the path tracer of the same --max-depth sums: a VPL of bounce k
// ends a path of k + 1 camera-side vertices. two_rooms is lit mostly by long paths. Each preview is
// the mean of eight VPL sets (one set's clustered sum moves the image mean by about 3 %), with a
// third of the default geometry clamp. Measured: -0.9 %, -1.8 %, -4.3 % at depths 2, 4, 32; VPLs one
// bounce short or long: -35 % or +34 % at depth 2; VPLs stopped at 8 bounces, as they once were:
// -10.2 % at depth 32.
TEST(Preview, SumsThePathsOfThePathTracersDepth) {
  for (const int depth : {2, 4, PathTracerSettings{}.maxDepth}) {
    RenderJobSettings s = settings("two_rooms.gltf", SamplingMode::Brdf, 1024);
    s.tracer.maxDepth = depth;
    const RenderJobResult reference = runRenderJob(s);
    s.mode = SamplingMode::Preview;
    s.spp = 16;
    s.preview.clampFraction = 0.01f;
    Image preview = reference.image;
    std::fill(preview.pixels.begin(), preview.pixels.end(), glm::vec3(0.0f));
    constexpr int kVplSets = 8;
    for (int set = 1; set <= kVplSets; ++set) {
      s.seed = uint64_t(set);
      const RenderJobResult one = runRenderJob(s);
      ASSERT_TRUE(allFinite(one.image));
      for (size_t i = 0; i < preview.pixels.size(); ++i) preview.pixels[i] += one.image.pixels[i] / float(kVplSets);
    }
    const double bias = relativeBias(preview, reference.image);
    std::printf("two_rooms at max depth %d: preview (8 VPL sets) against brdf, relative bias of the mean %+.4f\n", depth, bias);
    EXPECT_LT(std::abs(bias), 0.07) << "max depth " << depth;
  }
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
    const std::string path = test::builtInScene(scene);
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

// The pixel's own cluster choice (pixelChoiceShare) changes only how the clusters are drawn, not
// their sum: many passes with it and without it (the slice's choice alone) give the same image. The
// image means must agree within 3 %, and the median per-pixel squared difference of the two settings'
// images must stay under half the sum of each setting's difference between the halves of its passes
// (each half has half the passes, so that sum is four times the difference noise alone would give).
// The means' own noise: +1.3 % (cornell_glossy) and -1.0 % (two_rooms) at these 1024 passes, +0.34 %
// and +0.05 % at 16384; dividing by the wrong probability gave +15 % and +44 %.
TEST(Preview, PixelChoiceKeepsTheClusteredSum) {
  for (const std::string scene : {"cornell_glossy.gltf", "two_rooms.gltf"}) {
    const RenderScene rs(loadGltf(test::sourceDir() + "/scenes/" + scene));
    const Camera camera(defaultCamera(rs.data()), 32, 24);
    PreviewSettings own, slice;
    own.vpl.count = slice.vpl.count = 4096;
    slice.pixelChoiceShare = 0.0f;
    const VplField field = buildVplField(rs, camera, std::make_shared<VplSet>(traceVpls(rs, own.vpl)), own);
    struct Run {
      Image all, halfA, halfB;
    };
    const auto run = [&](const PreviewSettings& settings, uint64_t firstPass) {
      const TileRenderer renderer(camera, 5, previewShader(rs, field, settings));
      Film a(32, 24), b(32, 24);
      for (uint64_t pass = firstPass; pass < firstPass + 1024; ++pass) renderer.renderPass(pass % 2 ? b : a, pass);
      Run r{Image(32, 24), a.resolve(), b.resolve()};
      for (size_t i = 0; i < r.all.pixels.size(); ++i) r.all.pixels[i] = 0.5f * (r.halfA.pixels[i] + r.halfB.pixels[i]);
      return r;
    };
    const Run withPixel = run(own, 0), sliceOnly = run(slice, 4096);
    const double bias = relativeBias(withPixel.all, sliceOnly.all);
    const double between = medianRelativeSquaredError(withPixel.all, sliceOnly.all);
    const double halves = medianRelativeSquaredError(withPixel.halfA, withPixel.halfB) +
                          medianRelativeSquaredError(sliceOnly.halfA, sliceOnly.halfB);
    std::printf("%s: pixel choice against the slice's alone: mean %+.4f, median per-pixel error %.3g (halves' sum %.3g); means of the halves differ by %+.4f and %+.4f\n",
                scene.c_str(), bias, between, halves, relativeBias(withPixel.halfA, withPixel.halfB), relativeBias(sliceOnly.halfA, sliceOnly.halfB));
    EXPECT_LT(std::abs(bias), 0.03) << scene;
    EXPECT_LT(between, 0.5 * halves) << scene;
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

// Two independent preview images of one field (seeds 11 and 12): their mean is the estimate, half
// their difference has the same noise with zero mean.
struct TwoImages {
  Image a, b;
};
TwoImages renderTwice(const RenderScene& rs, const VplField& field, const PreviewSettings& ps, int passes) {
  const Camera camera(defaultCamera(rs.data()), kStructureWidth, kStructureHeight);
  Film a(camera.width(), camera.height()), b(camera.width(), camera.height());
  const TileRenderer first(camera, 11, previewShader(rs, field, ps)), second(camera, 12, previewShader(rs, field, ps));
  for (int pass = 0; pass < passes; ++pass) {
    first.renderPass(a, uint64_t(pass));
    second.renderPass(b, uint64_t(pass));
  }
  return {a.resolve(), b.resolve()};
}

// Whether two pixels' centres lie on one flat wall (one material, one plane).
bool samePlane(const RenderScene& rs, const CameraGather& gather, size_t p, size_t q) {
  const int32_t gp = gather.pixelGather[p], gq = gather.pixelGather[q];
  if (gp < 0 || gq < 0) return false;
  const SurfaceHit &hp = gather.hits[size_t(gp)], &hq = gather.hits[size_t(gq)];
  return hp.material == hq.material && glm::dot(hp.geometricNormal, hq.geometricNormal) >= 0.9999f &&
         std::abs(glm::dot(hp.position - hq.position, hp.geometricNormal)) <= 1e-4f * rs.radius();
}

// Pixels whose 3x3 neighbourhood lies on one wall: a pixel at an edge mixes two walls through its
// jittered rays, a real step that is not the preview's fault.
std::vector<uint8_t> flatPixels(const RenderScene& rs, const CameraGather& gather) {
  const int w = kStructureWidth, h = kStructureHeight;
  std::vector<uint8_t> flat(size_t(w) * size_t(h), 0);
  for (int y = 1; y + 1 < h; ++y)
    for (int x = 1; x + 1 < w; ++x) {
      bool all = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) all = all && samePlane(rs, gather, size_t(y * w + x), size_t((y + dy) * w + x + dx));
      flat[size_t(y * w + x)] = all;
    }
  return flat;
}

// Structure that passes cannot remove: on flat walls, the step between neighbouring pixels on either
// side of a slice border (of `sliced`), beyond what the noise explains, must be no larger than in an
// image without slices (one slice, one VPL per cluster: the plain VPL sum). A pair's excess is its
// squared step in the mean image minus the step's noise variance, relative to its brightness. The
// borders' excess is not zero without slices either (the VPL sum's own texture), hence the
// comparison. With a fixed representative per cluster and slice, the sliced image's border excess
// was 2.7x (Cornell box) and 2.6x (two_rooms) the slice-free one (and as large at 256 passes as at 64:
// bias, not noise); drawing members afresh, 1.5x and 0.8x.
double sliceBorderExcess(const RenderScene& rs, const VplField& sliced, const TwoImages& images) {
  const int w = kStructureWidth, h = kStructureHeight;
  const std::vector<uint8_t> flat = flatPixels(rs, sliced.gather);
  double excess = 0.0;
  size_t pairs = 0;
  auto visit = [&](int p, int q) {
    if (!flat[size_t(p)] || !flat[size_t(q)]) return;
    const int32_t gp = sliced.gather.pixelGather[size_t(p)], gq = sliced.gather.pixelGather[size_t(q)];
    if (sliced.tree.sliceOf[size_t(gp)] == sliced.tree.sliceOf[size_t(gq)]) return;
    const double ap = luminance(images.a.pixels[size_t(p)]), aq = luminance(images.a.pixels[size_t(q)]);
    const double bp = luminance(images.b.pixels[size_t(p)]), bq = luminance(images.b.pixels[size_t(q)]);
    const double mean = 0.25 * (ap + aq + bp + bq);
    if (!(mean > 0.0)) return;
    const double step = 0.5 * (ap + bp) - 0.5 * (aq + bq);
    const double noise = 0.25 * ((ap - bp) * (ap - bp) + (aq - bq) * (aq - bq));  // the step's variance, estimated
    excess += (step * step - noise) / (mean * mean);
    ++pairs;
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (x + 1 < w) visit(y * w + x, y * w + x + 1);
      if (y + 1 < h) visit(y * w + x, (y + 1) * w + x);
    }
  EXPECT_GT(pairs, 500u);
  return excess / double(std::max<size_t>(1, pairs));
}

// Lines: a row (or column) of a wall brighter or darker than the rows beside it. Per pixel, the
// noise of 48 passes hides a line of a few percent; along the line it adds up. The VPL sum has texture
// of its own (each VPL near a wall is a soft spot), so the measure is taken on the sliced image minus
// the slice-free one, of the same VPLs. Each run of a wall's pixels along a row sums its pixels'
// second differences across the row (a line has one sign along its whole length, noise has not),
// divided by that sum's noise (from the two images of each): t. Under noise alone t^2 averages 1, so
// z = sum(t^2 - 1) / sqrt(2 runs) is about standard normal; lines (or steps along rows) raise it.
// Each run is scaled by its own noise, so a run with a firefly counts no more than a clean one (with
// a mean of relative excesses instead, one such run outweighed lines painted into every ninth row).
double lineScore(const RenderScene& rs, const CameraGather& gather, const TwoImages& sliced, const TwoImages& whole) {
  const int w = kStructureWidth, h = kStructureHeight;
  const std::vector<uint8_t> flat = flatPixels(rs, gather);
  const auto lum = [](const Image& image, int p) { return double(luminance(image.pixels[size_t(p)])); };
  const auto difference = [&](int p) { return 0.5 * (lum(sliced.a, p) + lum(sliced.b, p) - lum(whole.a, p) - lum(whole.b, p)); };
  const auto variance = [&](int p) {  // of difference(p), estimated
    const double ds = lum(sliced.a, p) - lum(sliced.b, p), dw = lum(whole.a, p) - lum(whole.b, p);
    return 0.25 * (ds * ds + dw * dw);
  };
  double excess = 0.0;
  size_t runs = 0;
  // Runs along rows (or columns), second differences across them: to the pixels `across` away.
  const auto scan = [&](int lines, int length, int across, auto pixelAt) {
    for (int line = 0; line < lines; ++line) {
      double d2 = 0.0, var = 0.0;
      int n = 0, first = -1;
      const auto close = [&] {
        if (n >= 8 && var > 0.0) {
          excess += d2 * d2 / var - 1.0;
          ++runs;
        }
        d2 = var = 0.0;
        n = 0;
        first = -1;
      };
      for (int i = 0; i < length; ++i) {
        const int p = pixelAt(line, i);
        if (!flat[size_t(p)] || (first >= 0 && !samePlane(rs, gather, size_t(first), size_t(p)))) {
          close();
          if (!flat[size_t(p)]) continue;
        }
        if (first < 0) first = p;
        d2 += difference(p - across) - 2.0 * difference(p) + difference(p + across);
        var += variance(p - across) + 4.0 * variance(p) + variance(p + across);
        ++n;
      }
      close();
    }
  };
  scan(h, w, w, [&](int y, int x) { return y * w + x; });
  scan(w, h, 1, [&](int x, int y) { return y * w + x; });
  EXPECT_GT(runs, 500u);
  return excess / std::sqrt(2.0 * double(std::max<size_t>(1, runs)));
}

// The images with lines 3 % darker painted into every ninth row and column: what the line score must see.
TwoImages withPaintedLines(TwoImages images) {
  for (Image* image : {&images.a, &images.b})
    for (int y = 0; y < kStructureHeight; ++y)
      for (int x = 0; x < kStructureWidth; ++x)
        if (y % 9 == 4 || x % 9 == 4) image->at(x, y) *= 0.97f;
  return images;
}

TEST(Preview, PassesLeaveNoStepsOrLinesFromSlices) {
  for (const std::string scene : {"cornell_box.gltf", "two_rooms.gltf"}) {
    const RenderScene rs(loadGltf(test::sourceDir() + "/scenes/" + scene));
    const Camera camera(defaultCamera(rs.data()), kStructureWidth, kStructureHeight);
    PreviewSettings ps;
    ps.vpl.count = 4096;
    ps.slices.maxSliceSize = 64;  // many slices, many borders
    const auto vpls = std::make_shared<const VplSet>(traceVpls(rs, ps.vpl));
    const VplField sliced = buildVplField(rs, camera, vpls, ps);
    PreviewSettings plain = ps;  // one slice, a cluster per VPL: the VPL sum itself
    plain.slices.maxSliceSize = 1 << 20;
    plain.clustering.clusterBudget = plain.clustering.globalClusters = int(vpls->vpls.size());
    const VplField whole = buildVplField(rs, camera, vpls, plain);
    ASSERT_EQ(whole.tree.slices.size(), 1u);
    const TwoImages slicedImages = renderTwice(rs, sliced, ps, 48), wholeImages = renderTwice(rs, whole, plain, 48);
    const double withSlices = sliceBorderExcess(rs, sliced, slicedImages), without = sliceBorderExcess(rs, sliced, wholeImages);
    std::printf("%s: relative excess step across the borders of %zu slices %.4g, in the slice-free VPL sum %.4g (ratio %.2f)\n",
                scene.c_str(), sliced.tree.slices.size(), withSlices, without, withSlices / without);
    EXPECT_LT(withSlices, 2.0 * without) << scene;

    // Lines within the noise, and the score's own power: 3 % lines would fail it.
    constexpr double kMaxLineScore = 5.0;
    const double lines = lineScore(rs, sliced.gather, slicedImages, wholeImages);
    const double painted = lineScore(rs, sliced.gather, withPaintedLines(slicedImages), wholeImages);
    std::printf("%s: line score (about standard normal without lines) %.2f; with 3 %% lines painted in %.2f\n",
                scene.c_str(), lines, painted);
    EXPECT_LT(lines, kMaxLineScore) << scene;
    EXPECT_GT(painted, kMaxLineScore) << scene << ": the line score misses painted lines";
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
