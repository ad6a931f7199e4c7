#include "render/session/render_job.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include "render/core/error.h"
#include "render/core/stopwatch.h"
#include "render/film/film.h"
#include "render/guide/emitter_guide.h"
#include "render/guide/guide_builder.h"
#include "render/integrator/guided_continuation.h"
#include "render/scene/camera.h"
#include "render/scene/gltf_loader.h"
#include "render/session/film_learners.h"
#include "render/session/guide_switch.h"
#include "render/session/join_depth_trial.h"
#include "render/session/tile_renderer.h"
#include "render/session/window_switch.h"
#include "render/vpl/irradiance_grid.h"

namespace vpl {

namespace {

using Clock = SteadyClock;

// Raises a stop flag at a deadline, or earlier when destroyed.
class DeadlineWatch {
 public:
  DeadlineWatch(Clock::time_point deadline, std::atomic<bool>& flag)
      : thread_([this, deadline, &flag] {
          std::unique_lock lock(mutex_);
          if (!cv_.wait_until(lock, deadline, [this] { return done_; })) flag.store(true);
        }) {}
  ~DeadlineWatch() {
    { std::lock_guard lock(mutex_); done_ = true; }
    cv_.notify_all();
    thread_.join();
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool done_ = false;
  std::thread thread_;
};

}  // namespace

std::string RenderJobSettings::validate() const {
  if (scenePath.empty()) return "no scene given";
  if (width < 1 || height < 1 || width > 16384 || height > 16384) return "image size must be between 1 and 16384 pixels";
  if (timeBudget <= 0.0 && spp < 1) return "spp must be at least 1";
  if (timeBudget > 0.0 && !(timeBudget < 1e7)) return "time budget is too large";
  if (std::string e = tracer.validate(); !e.empty()) return e;
  if (std::string e = connections.validate(); !e.empty()) return e;
  if (std::string e = preview.validate(); !e.empty()) return e;
  if (std::string e = guide.validate(); !e.empty()) return e;
  return {};
}

RenderJobResult runRenderJob(const RenderJobSettings& settings, const std::function<void(double)>& progress) {
  if (std::string e = settings.validate(); !e.empty()) throw InputError(e);
  const auto start = Clock::now();
  SceneData data = loadGltf(settings.scenePath);
  const double load = secondsSince(start);
  RenderJobResult result = runRenderJob(settings, std::move(data), progress);
  result.timings.load = load;
  return result;
}

RenderJobResult runRenderJob(const RenderJobSettings& settings, SceneData data, const std::function<void(double)>& progress) {
  if (std::string e = settings.validate(); !e.empty()) throw InputError(e);
  RenderJobResult result;
  result.notices = data.notices;
  result.triangles = data.triangleCount();

  // Everything from here counts against --time: equal-time comparisons include preprocessing.
  const auto loaded = Clock::now();
  const auto deadline = loaded + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(settings.timeBudget));
  const RenderScene scene(std::move(data), settings.sky);
  result.timings.bvh = secondsSince(loaded);
  if (scene.usesDefaultSky()) result.notices.push_back("the scene has no light: lit by a uniform white sky (--sky to change, --sky 0 for none)");

  const Camera camera(defaultCamera(scene.data()), settings.width, settings.height);
  // VPLs (camera-independent), then slices and clusters for this camera.
  const bool vplRoulette = settings.tracer.roulette == RouletteRule::Vpl;
  std::shared_ptr<VplSet> vpls;
  if (settings.mode != SamplingMode::Brdf) {
    const auto t = Clock::now();
    vpls = std::make_shared<VplSet>(traceVpls(scene, vplSettingsForPaths(settings.preview.vpl, settings.tracer.maxDepth, settings.seed)));
    result.timings.vpl = secondsSince(t);
    result.rays += vpls->rays;
    result.vplCount = vpls->vpls.size();
  }
  // VPL connections: fresh light vertices every pass.
  const int connectionPaths = settings.connections.pathsFor(settings.width * settings.height, settings.mode);
  const bool connecting = connectionPaths > 0 && scene.emitters().supportsConnections();
  if (connectionPaths > 0 && !connecting && !scene.emitters().empty())
    result.notices.push_back("VPL connections are off: they do not support the sky or lights with a range");
  EmitterGuide emitterGuide(scene, settings.tracer.learnLights && settings.mode != SamplingMode::Preview);
  LightVertexCache connectionCache(settings.connections);
  const LightVertexCache* connections = connecting ? &connectionCache : nullptr;
  if (connecting) result.connectionPaths = connectionPaths;
  // The VPL weight window's estimate and a tracer that uses it: at once for the vpl rule, when the
  // switch turns on for auto.
  IrradianceGrid irradiance;
  const auto windowTracer = [&] {
    const auto t = Clock::now();
    irradiance = IrradianceGrid(scene, IrradianceGrid::kPhotons, settings.seed, settings.tracer.maxDepth);
    result.timings.irradiance = secondsSince(t);
    return std::make_unique<PathTracer>(scene, settings.tracer, &irradiance, connections, &emitterGuide);
  };
  std::unique_ptr<PathTracer> tracer =
      vplRoulette ? windowTracer() : std::make_unique<PathTracer>(scene, settings.tracer, nullptr, connections, &emitterGuide);
  VplField field;
  GuideField guide;
  std::optional<FilmLearners> learners;  // what the passes so far teach the guided continuations
  std::function<PixelShaderFactory(const PathTracer&)> shaderFor;
  if (settings.mode != SamplingMode::Brdf) {
    const auto t = Clock::now();
    PreviewSettings preview = settings.preview;
    preview.clustering.seed = settings.seed;
    field = buildVplField(scene, camera, vpls, preview);
    result.timings.cluster = secondsSince(t);
    result.timings.gather = field.gatherSeconds;
    result.timings.slices = field.sliceSeconds;
    result.timings.matrix = field.clusters.matrixSeconds;
    result.timings.globalClusters = field.clusters.globalSeconds;
    result.timings.refine = field.clusters.refineSeconds;
    result.rays += field.rays;
    result.sliceCount = field.tree.slices.size();
    size_t clusterTotal = 0;
    for (const SliceClusters& s : field.clusters.slices) clusterTotal += s.clusters.size();
    result.clustersPerSlice = field.tree.slices.empty() ? 0.0 : double(clusterTotal) / double(field.tree.slices.size());
    if (settings.mode == SamplingMode::Preview) {
      shaderFor = [&](const PathTracer&) { return previewShader(scene, field, settings.preview); };
    } else {
      const auto guideStart = Clock::now();
      guide = buildGuideField(scene, field, settings.guide);
      result.timings.guide = secondsSince(guideStart);
      result.timings.cluster = secondsSince(t);
      result.guideBytes = guide.memoryBytes();
      const SamplingMode mode = settings.mode;
      learners.emplace(guide, mode, settings.guide, TileRenderer::tileCountFor(settings.width, settings.height));
      const ContinuationFactory continuation = guidedContinuations(guide, mode, learners->logs());
      shaderFor = [continuation](const PathTracer& t) { return pathTracerShader(t, continuation); };
    }
  }
  std::optional<TileRenderer> renderer;
  std::optional<PathLanes> lanes;
  GuideSwitch guideSwitch;  // mis: whether BSDF samples in lanes have taken over
  const auto makeRenderer = [&] {
    if (settings.mode == SamplingMode::Brdf || guideSwitch.on()) {
      result.lanes = emplaceBsdfRenderer(renderer, lanes, camera, settings.seed, *tracer, settings.stratifiedSampler);
      return;
    }
    renderer.reset();  // its shader holds the old tracer
    renderer.emplace(camera, settings.seed, shaderFor(*tracer), settings.stratifiedSampler);
  };
  makeRenderer();
  Film film(settings.width, settings.height);
  // The auto rule: the film's first passes decide whether the window is used.
  const bool autoRoulette = settings.tracer.roulette == RouletteRule::Auto && settings.mode != SamplingMode::Preview;
  WindowSwitch window;

  // --join-depth auto: a few passes weighed for each candidate depth.
  std::optional<JoinDepthTrial> joinTrial;
  if (connecting && settings.connections.joinDepth == ConnectionSettings::kJoinDepthAuto)
    joinTrial.emplace(settings.width, settings.height);

  const auto renderStart = Clock::now();
  std::atomic<bool> stop{false};
  std::optional<DeadlineWatch> watch;
  const bool timed = settings.timeBudget > 0.0;
  if (timed) watch.emplace(deadline, stop);
  for (uint64_t pass = 0;; ++pass) {
    if (!timed && int(pass) >= settings.spp) break;
    if (timed && pass > 0 && stop.load()) break;
    emitterGuide.learnFromLastPass();
    if (connecting) {
      const auto t = Clock::now();
      connectionCache.build(scene, settings.seed, pass, connectionPaths, settings.tracer.maxDepth - 1, settings.stratifiedSampler,
                            &emitterGuide);
      result.timings.connections += secondsSince(t);
      result.rays += connectionCache.rays();
    }
    const JoinDepthTrial::PassTargets target = joinTrial ? joinTrial->beginPass(pass, film, connectionCache)
                                                        : JoinDepthTrial::PassTargets{film};
    // The first pass always completes: a budget never leaves an empty image.
    const PassStats stats = renderer->renderPass(target.film, pass, pass == 0 ? nullptr : &stop, target.counterfactual,
                                                 target.counterfactualDepth);
    if (joinTrial) joinTrial->endPass(pass, film, !(timed && stop.load()), stats, connectionCache);
    result.rays += stats.rays;
    result.samples += stats.samples;
    result.discarded += stats.discarded;
    result.bsdfSamples += stats.bsdfSamples;
    result.guideSamples += stats.guideSamples;
    result.proposals += stats.proposals;
    result.branches += stats.branches;
    result.accepted += stats.accepted;
    if (timed && pass > 0 && stop.load()) break;  // cut short: not a complete pass
    ++result.spp;
    if (pass == 0) result.firstImageSeconds = secondsSince(loaded);
    if (learners) {
      const auto t = Clock::now();
      learners->update();
      result.timings.guideLearning += secondsSince(t);
      if (settings.mode == SamplingMode::Mis && settings.guide.switchToLanes && !guideSwitch.decided() &&
          guideSwitch.update(uint64_t(result.spp), learners->guideGain(),
                             settings.stratifiedSampler && PathLanes::unsupported(*tracer).empty())) {
        result.guideSwitchPass = result.spp;
        makeRenderer();
      }
    }
    if (autoRoulette && !window.on() && WindowSwitch::updateDue(uint64_t(result.spp))) {
      if (window.update(film)) {
        result.windowFromPass = result.spp;
        renderer.reset();  // both hold the tracer being replaced
        lanes.reset();
        tracer = windowTracer();
        makeRenderer();
      }
    }
    if (progress) progress(timed ? std::min(1.0, secondsSince(loaded) / settings.timeBudget) : double(pass + 1) / settings.spp);
  }
  watch.reset();
  if (emitterGuide.active()) result.learnedLightRegions = emitterGuide.learnedRegionShare();
  if (learners) {
    result.learnedBsdfProbability = learners->meanBsdfProbability();
    result.guideGain = learners->guideGain();
    result.learnedGuideShare = learners->meanGuideShare();
  }
  if (joinTrial && joinTrial->decided()) {
    result.joinDepthChosen = joinTrial->chosen();
    result.joinDepthScores.assign(joinTrial->scores().begin(), joinTrial->scores().end());
  }
  result.timings.render = secondsSince(renderStart);
  result.seconds = secondsSince(loaded);
  result.image = film.resolve();
  return result;
}

}  // namespace vpl
