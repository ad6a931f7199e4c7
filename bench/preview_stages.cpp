// Where the preview's time goes (issue 17): for each scene and window size, the wall seconds of every
// stage of the full preview as the viewer builds it (VPLs, gather points, slice tree, LightSlice's
// reduced matrix, global clustering and per-slice refinement, the guide, one preview pass), the same
// for the coarse first preview (coarsePreviewSettings; half size past CoarsePreview::maxPixels), and
// the viewer session's own figures: from a restart to its first preview image, at opening (VPLs
// traced) and after a camera move (VPLs kept), and to the start of path-traced refinement (mis).
// Prints one Markdown table row per scene and size; median of `runs` runs per figure.
// Usage: preview_stages [--threads N] [--runs N] [--sizes 320x240,640x360,1280x720] SCENE...
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>
#include <tbb/global_control.h>
#include "render/core/error.h"
#include "render/core/stopwatch.h"
#include "render/film/film.h"
#include "render/guide/guide_builder.h"
#include "render/scene/gltf_loader.h"
#include "render/session/progressive_session.h"
#include "render/session/tile_renderer.h"

using namespace vpl;

namespace {

struct Figures {
  double vpl = 0, gather = 0, slices = 0, matrix = 0, global = 0, refine = 0, guide = 0, pass = 0;
  double coarseField = 0, coarsePass = 0;
  double sessionOpen = 0, sessionMove = 0, refineStart = 0;
  size_t sliceCount = 0, coarseSlices = 0;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// Restart -> first preview image of a session that renders in `preview` mode.
double sessionFirstPreview(const std::shared_ptr<const RenderScene>& scene, int w, int h, int threads, bool move) {
  SessionSettings settings;
  settings.mode = SamplingMode::Preview;
  settings.width = w;
  settings.height = h;
  settings.threads = threads;
  CameraData camera = defaultCamera(scene->data());
  ProgressiveSession session(scene, camera, settings);
  auto waitPreview = [&session] {
    for (int i = 0; i < 60000 && session.stats().firstPreviewSeconds == 0.0; ++i)
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    return session.stats().firstPreviewSeconds;
  };
  const double opened = waitPreview();
  if (!move) return opened;
  const uint64_t restarts = session.stats().restarts;
  camera.eye += glm::vec3(0.02f * scene->radius(), 0.0f, 0.0f);
  session.setCamera(camera);
  while (session.stats().restarts == restarts) std::this_thread::sleep_for(std::chrono::microseconds(200));
  return waitPreview();
}

// Opening -> the first path-traced pass begins, in the default (guided) mode.
double sessionRefineStart(const std::shared_ptr<const RenderScene>& scene, int w, int h, int threads) {
  SessionSettings settings;
  settings.width = w;
  settings.height = h;
  settings.threads = threads;
  ProgressiveSession session(scene, defaultCamera(scene->data()), settings);
  for (int i = 0; i < 120000 && session.stats().refineStartSeconds == 0.0; ++i)
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  return session.stats().refineStartSeconds;
}

Figures measure(const std::shared_ptr<const RenderScene>& scene, int w, int h, int threads) {
  Figures f;
  const SessionSettings defaults;
  const Camera camera(defaultCamera(scene->data()), w, h);
  Stopwatch watch;
  auto vpls = std::make_shared<const VplSet>(traceVpls(*scene, defaults.preview.vpl));
  f.vpl = watch.lap();

  const PreviewSettings full = withAtMostSlices(defaults.preview, size_t(w) * size_t(h), defaults.maxSlices);
  const VplField field = buildVplField(*scene, camera, vpls, full);
  watch.lap();
  f.gather = field.gatherSeconds;
  f.slices = field.sliceSeconds;
  f.matrix = field.clusters.matrixSeconds;
  f.global = field.clusters.globalSeconds;
  f.refine = field.clusters.refineSeconds;
  f.sliceCount = field.tree.slices.size();
  const GuideField guide = buildGuideField(*scene, field, defaults.guide);
  f.guide = watch.lap();
  Film film(w, h);
  TileRenderer(camera, 1, previewShader(*scene, field, full)).renderPass(film, 0);
  f.pass = watch.lap();

  const int divisor = coarsePreviewDivisor(w, h);
  const Camera coarseCamera(defaultCamera(scene->data()), std::max(1, w / divisor), std::max(1, h / divisor));
  const PreviewSettings coarse = coarsePreviewSettings(full, size_t(coarseCamera.width()) * size_t(coarseCamera.height()));
  const VplField coarseField = buildVplField(*scene, coarseCamera, vpls, coarse);
  f.coarseField = watch.lap();
  f.coarseSlices = coarseField.tree.slices.size();
  Film coarseFilm(coarseCamera.width(), coarseCamera.height());
  TileRenderer(coarseCamera, 1, previewShader(*scene, coarseField, coarse)).renderPass(coarseFilm, 0);
  f.coarsePass = watch.lap();

  f.sessionOpen = sessionFirstPreview(scene, w, h, threads, false);
  f.sessionMove = sessionFirstPreview(scene, w, h, threads, true);
  f.refineStart = sessionRefineStart(scene, w, h, threads);
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  int threads = 2, runs = 3;
  std::vector<std::pair<int, int>> sizes = {{320, 240}, {640, 360}, {1280, 720}};
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--threads" && i + 1 < argc) {
      threads = std::atoi(argv[++i]);
    } else if (a == "--runs" && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--sizes" && i + 1 < argc) {
      sizes.clear();
      for (char* tok = std::strtok(argv[++i], ","); tok; tok = std::strtok(nullptr, ",")) {
        int w = 0, h = 0;
        if (std::sscanf(tok, "%dx%d", &w, &h) == 2 && w > 0 && h > 0) sizes.push_back({w, h});
      }
    } else {
      scenes.push_back(a);
    }
  }
  if (scenes.empty() || sizes.empty() || threads < 1) {
    std::fprintf(stderr, "usage: preview_stages [--threads N] [--runs N] [--sizes WxH,...] SCENE...\n");
    return 2;
  }
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  std::printf("Seconds, %d threads, median of %d runs. Full: the preview as the viewer builds it after the coarse pass; "
              "first preview: VPLs + coarse field + its pass; session: restart -> first preview image (incl. the quick "
              "stage), at opening / after a camera move; refine: opening -> the first path-traced pass (mis).\n\n",
              threads, runs);
  std::printf("| scene | size | VPLs | gather | slices | matrix | global | refine | guide | pass | full preview | "
              "coarse field | coarse pass | **first preview** | session open | session move | refine |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  try {
    for (const std::string& path : scenes) {
      const auto scene = std::make_shared<const RenderScene>(loadGltf(path));
      std::string name = path.substr(path.find_last_of('/') + 1);
      name = name.substr(0, name.find_last_of('.'));
      for (const auto& [w, h] : sizes) {
        std::vector<Figures> all;
        for (int r = 0; r < runs; ++r) all.push_back(measure(scene, w, h, threads));
        auto med = [&all](double Figures::*m) {
          std::vector<double> v;
          for (const Figures& f : all) v.push_back(f.*m);
          return median(v);
        };
        const double fullPreview = med(&Figures::vpl) + med(&Figures::gather) + med(&Figures::slices) +
                                   med(&Figures::matrix) + med(&Figures::global) + med(&Figures::refine) + med(&Figures::pass);
        const double first = med(&Figures::vpl) + med(&Figures::coarseField) + med(&Figures::coarsePass);
        std::printf("| %s | %dx%d (%zu / %zu slices) | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | "
                    "%.3f | **%.3f** | %.3f | %.3f | %.3f |\n",
                    name.c_str(), w, h, all[0].sliceCount, all[0].coarseSlices, med(&Figures::vpl), med(&Figures::gather),
                    med(&Figures::slices), med(&Figures::matrix), med(&Figures::global), med(&Figures::refine),
                    med(&Figures::guide), med(&Figures::pass), fullPreview, med(&Figures::coarseField),
                    med(&Figures::coarsePass), first, med(&Figures::sessionOpen), med(&Figures::sessionMove),
                    med(&Figures::refineStart));
        std::fflush(stdout);
      }
    }
  } catch (const InputError& e) {
    std::fprintf(stderr, "preview_stages: %s\n", e.what());
    return 2;
  }
  return 0;
}
