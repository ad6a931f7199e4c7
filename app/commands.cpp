#include "app/commands.h"

#include <cstdio>
#include <sstream>
#include <unistd.h>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include "render/core/error.h"
#include "render/film/image_io.h"
#include "render/film/image_metrics.h"
#include "render/session/progress_bar.h"
#include "render/session/render_job.h"
#include "render/session/ray_benchmark.h"
#include "app/converge.h"
#include "app/sweep.h"
#include "app/render_options.h"
#include "ui/osmesa_capture.h"
#include "ui/viewer.h"

namespace vpl::app {

namespace {

RenderOptions gRender, gBench, gCapture, gReference, gConverge, gSweep;
ConvergeOptions gConvergeOnly;
SweepOptions gSweepOnly;
constexpr uint64_t kReferenceSeed = 1000;
CLI::App* gReferenceCommand = nullptr;
CLI::App* gConvergeCommand = nullptr;
CLI::App* gSweepCommand = nullptr;
CLI::App* gRenderCommand = nullptr;
CLI::App* gCaptureCommand = nullptr;
RenderOptions gViewer;  // the viewer reuses the mode, size, seed, thread, exposure and VPL/guide flags
std::string gScreenshot, gStatsLog;
bool gScreenshotPanel = false;
double gScreenshotAfter = 3.0;
CLI::App* gBenchCommand = nullptr;
CLI::App* gCompareCommand = nullptr;
std::string gCompareImage, gCompareReference, gCompareMap;

nlohmann::ordered_json summaryJson(const RenderJobSettings& s, const RenderJobResult& r) {
  nlohmann::ordered_json j;
  j["mode"] = modeName(s.mode);
  j["width"] = s.width;
  j["height"] = s.height;
  j["spp"] = r.spp;
  j["seconds"] = r.seconds;
  j["timings"] = {{"load", r.timings.load}, {"bvh", r.timings.bvh}, {"vpl", r.timings.vpl},
                  {"cluster", r.timings.cluster}, {"irradiance", r.timings.irradiance}, {"render", r.timings.render}};
  if (s.mode != SamplingMode::Brdf)
    j["cluster_stages"] = {{"gather", r.timings.gather},          {"slices", r.timings.slices},
                           {"matrix", r.timings.matrix},          {"global", r.timings.globalClusters},
                           {"refine", r.timings.refine},          {"guide", r.timings.guide}};
  j["first_image_s"] = r.firstImageSeconds;
  j["rays"] = r.rays;
  j["rays_per_s"] = r.timings.render > 0 ? double(r.rays) / r.timings.render : 0.0;
  j["samples_per_s"] = r.timings.render > 0 ? double(r.samples) / r.timings.render : 0.0;
  j["discarded"] = r.discarded;
  j["bsdf_samples"] = r.bsdfSamples;
  j["guide_samples"] = r.guideSamples;
  j["triangles"] = r.triangles;
  // Paths traced at once: 8 where brdf's lanes applied (render/integrator/path_lanes.h), else 1.
  j["lanes"] = r.lanes;
  // Learned next-event estimation: the share of the scene's regions that sample from what they learned
  // (null: off, or not for this scene's lights).
  if (s.mode != SamplingMode::Preview)
    j["light_learning_regions"] = r.learnedLightRegions >= 0.0 ? nlohmann::json(r.learnedLightRegions) : nlohmann::json(nullptr);
  if (s.mode != SamplingMode::Brdf) {
    j["vpls"] = r.vplCount;
    j[s.mode == SamplingMode::Preview ? "slices" : "cache_points"] = r.sliceCount;
    j[s.mode == SamplingMode::Preview ? "clusters_per_slice" : "clusters_per_cache_point"] = r.clustersPerSlice;
  }
  if (s.mode == SamplingMode::Metropolis || s.mode == SamplingMode::Mis || s.mode == SamplingMode::Mixture) {
    j["acceptance"] = r.proposals > 0 ? double(r.accepted) / double(r.proposals) : 0.0;
    j["guide_bytes"] = r.guideBytes;
    j["guide_learning"] = s.guide.learnDirections;
    if (s.guide.learnDirections) {
      j["guide_prior"] = s.guide.vplPrior ? "vpl" : "none";
      j["guide_learned_share"] = r.learnedGuideShare;
      j["guide_learning_s"] = r.timings.guideLearning;
    }
  }
  if (s.mode == SamplingMode::Mis) {  // learned: the mean over cache points with enough samples (null: none yet)
    if (!s.guide.learnSelection) j["bsdf_prob"] = s.guide.bsdfProbability;
    else if (r.learnedBsdfProbability >= 0.0) j["bsdf_prob"] = r.learnedBsdfProbability;
    else j["bsdf_prob"] = nullptr;
    if (r.guideGain >= 0.0) j["guide_gain"] = r.guideGain;
    if (s.mode == SamplingMode::Mis) j["guide_switch_pass"] = r.guideSwitchPass;
  }
  if (r.connectionPaths > 0) {
    j["connect_paths"] = r.connectionPaths;
    j["connect_paths_s"] = r.timings.connections;  // tracing them, all passes (inside the render phase)
    j["joins_per_vertex"] = s.connections.joinsPerVertex;
    if (s.connections.joinDepth == ConnectionSettings::kJoinDepthAuto) {
      // The depth the trial chose (null: the render ended before it decided; its passes joined at every vertex).
      j["join_depth"] = "auto";
      if (r.joinDepthChosen) j["join_depth_chosen"] = *r.joinDepthChosen;
      else j["join_depth_chosen"] = nullptr;
      j["join_depth_scores"] = r.joinDepthScores;
    } else {
      j["join_depth"] = s.connections.joinDepth;
    }
    j["join_roulette"] = s.connections.shadowRoulette;
  }
  if (s.tracer.roulette == RouletteRule::Vpl || s.tracer.roulette == RouletteRule::Auto)
    j["branches_per_sample"] = r.samples > 0 ? double(r.branches) / double(r.samples) : 0.0;
  if (s.tracer.roulette == RouletteRule::Auto) j["window_from_pass"] = r.windowFromPass;
  j["sampler"] = s.stratifiedSampler ? "sobol" : "random";
  j["seed"] = s.seed;
  j["threads"] = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  j["scene"] = s.scenePath;
  return j;
}

// A render job with the progress bar on a terminal and the scene's notices on stderr.
RenderJobResult renderWithProgress(const RenderJobSettings& settings, const char* label) {
  ProgressBar bar(label, isatty(STDERR_FILENO) != 0);
  RenderJobResult result = runRenderJob(settings, [&](double f) { bar.update(f, ""); });
  bar.finish();
  for (const std::string& notice : result.notices) std::fprintf(stderr, "vplview: note: %s\n", notice.c_str());
  return result;
}

int runRender(const RenderOptions& options) {
  const RenderJobSettings settings = options.toSettings();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, options.threadCount());
  // Check the outputs before spending minutes on a render that cannot be saved.
  checkWritable(options.out, "exr");
  if (!options.png.empty()) checkWritable(options.png, "png");
  const RenderJobResult result = renderWithProgress(settings, "render");

  writeExr(options.out, result.image);
  if (!options.png.empty()) writePng(options.png, result.image, options.exposure);
  std::printf("%s\n", summaryJson(settings, result).dump().c_str());
  return 0;
}

int runBench() {
  RenderJobSettings settings = gBench.toSettings();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, gBench.threadCount());
  const RenderJobResult result = runRenderJob(settings);
  const double pathRate = result.timings.render > 0 ? double(result.rays) / result.timings.render : 0.0;
  const RayBenchmark raw = measureRawRayRate(settings.scenePath, gBench.rawSeconds, settings.seed);
  nlohmann::ordered_json j = summaryJson(settings, result);
  j["raw_rays_per_s"] = raw.raysPerSecond;
  j["raw_rays"] = raw.rays;
  j["path_vs_raw"] = raw.raysPerSecond > 0 ? pathRate / raw.raysPerSecond : 0.0;
  std::fprintf(stderr, "path tracer %.3g rays/s, raw Embree %.3g rays/s (incoherent rtcIntersect1), ratio %.2f\n",
               pathRate, raw.raysPerSecond, j["path_vs_raw"].get<double>());
  std::printf("%s\n", j.dump().c_str());
  return 0;
}

int runCapture() {
  RenderJobSettings settings = gCapture.toSettings();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, gCapture.threadCount());
  checkWritable(gCapture.out, "png");
  const RenderJobResult result = renderWithProgress(settings, "capture");
  // Through the viewer's own display code, in a software OpenGL context.
  writePngBytes(gCapture.out, result.image.width, result.image.height,
                ui::captureThroughDisplay(result.image, gCapture.exposure));
  nlohmann::ordered_json j = summaryJson(settings, result);
  j["capture"] = gCapture.out;
  std::printf("%s\n", j.dump().c_str());
  return 0;
}

int runViewerCommand() {
  ui::ViewerOptions options;
  options.scenePath = gViewer.scene.empty() ? std::string(VPLVIEW_DEFAULT_SCENE) : gViewer.scene;
  const RenderJobSettings s = gViewer.toSettings();
  options.session.mode = s.mode;
  options.session.seed = s.seed;
  options.session.threads = gViewer.threads;
  options.session.tracer = s.tracer;
  options.session.connections = s.connections;
  options.session.preview = s.preview;
  options.session.guide = s.guide;
  options.session.stratifiedSampler = s.stratifiedSampler;
  options.sky = s.sky;
  options.windowWidth = gViewer.width;
  options.windowHeight = gViewer.height;
  options.exposure = gViewer.exposure;
  options.screenshot = gScreenshot;
  options.screenshotAfter = gScreenshotAfter;
  options.statsLog = gStatsLog;
  options.screenshotPanel = gScreenshotPanel;
  if (!gScreenshot.empty()) checkWritable(gScreenshot, "png");
  return ui::runViewer(options);
}

int runCompare() {
  const Image image = readExr(gCompareImage), reference = readExr(gCompareReference);
  nlohmann::ordered_json j;
  j["image"] = gCompareImage;
  j["reference"] = gCompareReference;
  j["relmse"] = relMse(image, reference);
  j["bias"] = relativeBias(image, reference);
  if (!gCompareMap.empty()) {
    checkWritable(gCompareMap, "png");
    writePng(gCompareMap, falseColourLog(relMseMap(image, reference)));
    j["error_map"] = gCompareMap;
  }
  std::printf("%s\n", j.dump().c_str());
  return 0;
}

}  // namespace

void registerCommands(CLI::App& app) {
  gRenderCommand = app.add_subcommand("render", "render a scene headlessly to EXR (and PNG)");
  gRender.addTo(*gRenderCommand, /*requireOut=*/true);

  gReferenceCommand = app.add_subcommand("reference", "render a reference for relMSE measurements (EXR; brdf unless --mode, seed 1000 unless --seed)");
  gReference.addTo(*gReferenceCommand, /*requireOut=*/true);

  gConvergeCommand = app.add_subcommand("converge", "relMSE and bias of each mode against a reference at growing time budgets");
  gConverge.addConvergeTo(*gConvergeCommand);
  gConvergeOnly.addTo(*gConvergeCommand);

  gSweepCommand = app.add_subcommand("sweep", "equal-time relMSE of each value of one or more render flags against a reference");
  gSweepCommand->footer("example: vplview sweep SCENE --reference REF.exr --modes mis --times 10 --vary --clusters=50,100,200,400");
  gSweep.addConvergeTo(*gSweepCommand);
  gSweepOnly.addTo(*gSweepCommand);

  gCaptureCommand = app.add_subcommand("capture", "render headlessly and save what the viewer's display would show (OSMesa)");
  gCapture.addTo(*gCaptureCommand, /*requireOut=*/true);

  // No subcommand: the viewer, on SCENE or the built-in Cornell box.
  gViewer.mode = "mis";
  gViewer.width = 1280;
  gViewer.height = 720;
  gViewer.addViewerOptionsTo(app);
  app.add_option("--screenshot", gScreenshot, "viewer: save what the window shows as PNG, then exit");
  app.add_option("--screenshot-after", gScreenshotAfter, "viewer: seconds of rendering before --screenshot")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--screenshot-panel", gScreenshotPanel, "viewer: keep the panel in the screenshot");
  app.add_option("--stats-log", gStatsLog, "viewer: write frame rate and session figures once a second to this file");

  gBenchCommand = app.add_subcommand("bench", "path tracer rays/s against the raw Embree rate on the same scene");
  gBench.addTo(*gBenchCommand, /*requireOut=*/false);
  gBenchCommand->add_option("--raw-seconds", gBench.rawSeconds, "seconds of raw incoherent rtcIntersect1 rays")
      ->check(CLI::PositiveNumber);

  gCompareCommand = app.add_subcommand("compare", "relMSE and relative bias of an EXR image against a reference EXR");
  gCompareCommand->add_option("image", gCompareImage, "image (OpenEXR)")->required();
  gCompareCommand->add_option("reference", gCompareReference, "reference (OpenEXR)")->required();
  gCompareCommand->add_option("--error-map", gCompareMap,
                              "PNG of the per-pixel relMSE, log scale: black 1e-4, blue, red, yellow, white >= 1");
}

int runSelectedCommand(CLI::App& app) {
  if (gCompareCommand->parsed()) return runCompare();
  if (gRenderCommand->parsed()) return runRender(gRender);
  if (gReferenceCommand->parsed()) {
    // Renders default to seed 1: a reference with the same random numbers would flatter them.
    if (gReferenceCommand->count("--seed") == 0) gReference.seed = kReferenceSeed;
    return runRender(gReference);
  }
  if (gConvergeCommand->parsed()) return runConverge(gConvergeOnly, gConverge, *gConvergeCommand);
  if (gSweepCommand->parsed()) return runSweep(gSweepOnly, gSweep, *gSweepCommand);
  if (gBenchCommand->parsed()) return runBench();
  if (gCaptureCommand->parsed()) return runCapture();
  (void)app;
  return runViewerCommand();
}

}  // namespace vpl::app
