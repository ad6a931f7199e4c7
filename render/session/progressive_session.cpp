#include "render/session/progressive_session.h"

#include <chrono>
#include <map>
#include <tbb/info.h>
#include <tbb/task_arena.h>
#include "render/core/stopwatch.h"
#include "render/film/crossfade.h"
#include "render/film/film.h"
#include "render/guide/guide_builder.h"
#include "render/integrator/guided_continuation.h"
#include "render/guide/emitter_guide.h"
#include "render/session/film_learners.h"
#include "render/session/tile_renderer.h"
#include "render/session/guide_switch.h"
#include "render/session/join_depth_trial.h"
#include "render/session/window_switch.h"

namespace vpl {

namespace {

// Clusters per pixel in the preview passes that bridge a refining mode's start.
constexpr int kBridgingClustersPerPass = 2;

using Clock = SteadyClock;

// The quick stage renders at this fraction of the size, and keeps refining it until the camera has
// been still this long: only then does the (not cancellable) clustering start.
constexpr int kQuickDivisor = 4;
constexpr double kStillSeconds = 0.15;

Image upscaleNearest(const Image& small, int width, int height) {
  Image out(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      out.at(x, y) = small.at(std::min(small.width - 1, x * small.width / width), std::min(small.height - 1, y * small.height / height));
  return out;
}

}  // namespace

const char* stageName(SessionStage stage) {
  switch (stage) {
    case SessionStage::Quick: return "quick";
    case SessionStage::Coarse: return "coarse";
    case SessionStage::Preview: return "preview";
    case SessionStage::Refine: return "refine";
    case SessionStage::Done: return "done";
  }
  return "?";
}

struct ProgressiveSession::Request {
  CameraData camera;
  SamplingMode mode;
  int width, height;
};

// What the controller keeps for one camera and size; dropped when either changes.
struct ProgressiveSession::CameraState {
  struct ModeFilm {
    std::unique_ptr<Film> film;
    uint64_t nextPass = 0;  // passes started (a cancelled pass still used its index)
    int complete = 0;
    WindowSwitch window;  // the auto roulette rule's decision for this film
    std::unique_ptr<FilmLearners> learners;     // what this film's passes teach the guided continuations
    std::unique_ptr<LightVertexCache> joins;    // VPL connections: its choice of vertices learns from this film's passes
    std::unique_ptr<EmitterGuide> lights;       // learned next-event estimation, from this film's passes
    std::unique_ptr<JoinDepthTrial> joinTrial;  // --join-depth auto: which depth this film's passes join to
    GuideSwitch guideSwitch;                    // mis: whether BSDF samples in lanes took over this film
    bool joinDepthAdopted = false;              // joins to the depth an earlier view's trial chose
    double variance = -1.0;  // relative variance per sample after SceneDecisions::kVariancePass passes
  };
  std::optional<Request> key;
  Clock::time_point restart = Clock::now();
  std::unique_ptr<Film> quick;
  uint64_t quickPasses = 0;
  std::unique_ptr<VplField> field;
  ModeFilm preview;
  std::unique_ptr<GuideField> guide;
  std::map<SamplingMode, ModeFilm> films;
  uint64_t samples = 0, rays = 0;
  double renderSeconds = 0.0;
};

ProgressiveSession::ProgressiveSession(std::shared_ptr<const RenderScene> scene, const CameraData& camera,
                                       const SessionSettings& settings)
    : scene_(std::move(scene)), settings_(settings), tracer_(*scene_, settings.tracer), camera_(camera) {
  stats_.mode = settings.mode;
  pending_ = std::make_unique<Request>(Request{camera, settings.mode, settings.width, settings.height});
  controller_ = std::thread([this] { controllerLoop(); });
}

ProgressiveSession::~ProgressiveSession() {
  {
    std::lock_guard lock(mutex_);
    quit_ = true;
    cancel_.store(true);
  }
  changed_.notify_all();
  controller_.join();
}

void ProgressiveSession::requestRestart() {
  // The state under mutex_ is always the newest the UI asked for: the request is simply a copy of it.
  pending_ = std::make_unique<Request>(Request{camera_, stats_.mode, settings_.width, settings_.height});
  cancel_.store(true);
  changed_.notify_all();
}

void ProgressiveSession::setCamera(const CameraData& camera) {
  std::lock_guard lock(mutex_);
  camera_ = camera;
  requestRestart();
}

void ProgressiveSession::setMode(SamplingMode mode) {
  std::lock_guard lock(mutex_);
  stats_.mode = mode;
  requestRestart();
}

void ProgressiveSession::resize(int width, int height) {
  if (width < 1 || height < 1) return;
  std::lock_guard lock(mutex_);
  if (width == settings_.width && height == settings_.height) return;
  settings_.width = width;
  settings_.height = height;
  requestRestart();
}

bool ProgressiveSession::latestImage(Image& out, uint64_t& version, Image* variance) const {
  std::lock_guard lock(mutex_);
  if (version_ == version) return false;
  out = shown_;
  if (variance) *variance = shownVariance_.width > 0 ? shownVariance_ : Image(shown_.width, shown_.height);
  version = version_;
  return true;
}

ProgressiveSession::Estimate ProgressiveSession::latestEstimate() const {
  std::lock_guard lock(mutex_);
  return {estimate_.width > 0 ? estimate_ : shown_, stats_.stage, stats_.spp};
}

SessionStats ProgressiveSession::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

CameraData ProgressiveSession::camera() const {
  std::lock_guard lock(mutex_);
  return camera_;
}

bool ProgressiveSession::waitUntilDone(double seconds) const {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return idle_ && !pending_; });
}

void ProgressiveSession::publish(const Image& image, SessionStage stage, int spp, Image variance, Image estimate) {
  std::lock_guard lock(mutex_);
  shown_ = image;
  shownVariance_ = std::move(variance);
  estimate_ = std::move(estimate);
  ++version_;
  stats_.stage = stage;
  stats_.spp = spp;
}

void ProgressiveSession::controllerLoop() {
  const int threads = settings_.threads > 0 ? settings_.threads : tbb::info::default_concurrency();
  tbb::task_arena arena(threads);
  CameraState state;
  for (;;) {
    Request request;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [this] { return quit_ || pending_ != nullptr; });
      if (quit_) return;
      request = *pending_;
      pending_.reset();
      idle_ = false;
      cancel_.store(false);
    }
    const bool sameView = state.key && state.key->width == request.width && state.key->height == request.height &&
                          state.key->camera.eye == request.camera.eye && state.key->camera.target == request.camera.target &&
                          state.key->camera.up == request.camera.up && state.key->camera.yfov == request.camera.yfov;
    if (!sameView) {
      const uint64_t samples = state.samples, rays = state.rays;
      const double seconds = state.renderSeconds;
      state = CameraState();
      state.samples = samples;  // rates are per session, not per view
      state.rays = rays;
      state.renderSeconds = seconds;
      std::lock_guard lock(mutex_);
      ++stats_.restarts;
      stats_.firstPreviewSeconds = stats_.refineStartSeconds = 0.0;
      stats_.learnedBsdfProbability = -1.0;
      stats_.learnedGuideShare = -1.0;
      stats_.guideSwitchPass = 0;
      stats_.guideGain = -1.0;
      stats_.guideSwitchAdopted = stats_.joinDepthAdopted = false;
    }
    state.key = request;
    arena.execute([&] { runUntilChanged(state, request); });
    std::lock_guard lock(mutex_);
    if (!cancelled() && !pending_) {
      idle_ = true;
      stats_.stage = SessionStage::Done;
      changed_.notify_all();
    }
  }
}

void ProgressiveSession::runUntilChanged(CameraState& state, const Request& request) {
  const RenderScene& scene = *scene_;
  const int w = request.width, h = request.height;
  auto noteTime = [&] {
    std::lock_guard lock(mutex_);
    stats_.sinceRestart = secondsSince(state.restart);
  };
  auto notePreview = [&] {
    std::lock_guard lock(mutex_);
    if (stats_.firstPreviewSeconds == 0.0) stats_.firstPreviewSeconds = secondsSince(state.restart);
  };

  // 1. Quick: quarter-size BSDF passes until the camera has been still for a moment.
  if (!state.field) {
    const Camera small(request.camera, std::max(1, w / kQuickDivisor), std::max(1, h / kQuickDivisor));
    if (!state.quick) state.quick = std::make_unique<Film>(small.width(), small.height());
    std::optional<TileRenderer> renderer;
    std::optional<PathLanes> lanes;
    emplaceBsdfRenderer(renderer, lanes, small, settings_.seed, tracer_, settings_.stratifiedSampler);
    do {
      // The first quick pass always completes: a restart never leaves the window without a frame.
      const uint64_t pass = state.quickPasses++;
      renderer->renderPass(*state.quick, pass, pass > 0 ? &cancel_ : nullptr);
      if (cancelled()) return;
      publish(upscaleNearest(state.quick->resolve(), w, h), SessionStage::Quick, int(state.quickPasses));
      if (state.quickPasses == 1) {
        std::lock_guard lock(mutex_);
        stats_.firstFrameSeconds = secondsSince(state.restart);
      }
      noteTime();
    } while (secondsSince(state.restart) < kStillSeconds);
  }

  // 2. Preview: VPLs once per scene, this view's slices and clusters, a few preview passes.
  const Camera camera(request.camera, w, h);
  if (!state.field) {
    auto t = Clock::now();
    if (!vpls_) {
      vpls_ = std::make_shared<const VplSet>(
          traceVpls(scene, vplSettingsForPaths(settings_.preview.vpl, settings_.tracer.maxDepth, settings_.seed)));
    }
    const double vplSeconds = secondsSince(t);
    t = Clock::now();
    PreviewSettings preview = settings_.maxSlices > 0 ? withAtMostSlices(settings_.preview, size_t(w) * size_t(h), settings_.maxSlices)
                                                      : settings_.preview;
    preview.clustering.seed = settings_.seed;
    if (settings_.coarsePreview) {
      // One coarse pass on screen while the full clustering runs; its film is not kept.
      const int divisor = coarsePreviewDivisor(w, h);
      const Camera coarseCamera(request.camera, std::max(1, w / divisor), std::max(1, h / divisor));
      const size_t coarsePixels = size_t(coarseCamera.width()) * size_t(coarseCamera.height());
      const PreviewSettings coarse = coarsePreviewSettings(preview, coarsePixels);
      const VplField coarseField = buildVplField(scene, coarseCamera, vpls_, coarse, &cancel_);
      if (cancelled()) return;
      Film film(coarseCamera.width(), coarseCamera.height());
      TileRenderer(coarseCamera, settings_.seed, previewShader(scene, coarseField, coarse), settings_.stratifiedSampler)
          .renderPass(film, 0, &cancel_);
      if (cancelled()) return;
      publish(divisor > 1 ? upscaleNearest(film.resolve(), w, h) : film.resolve(), SessionStage::Coarse, 1);
      notePreview();
    }
    auto field = std::make_unique<VplField>(buildVplField(scene, camera, vpls_, preview, &cancel_));
    if (cancelled()) return;  // incomplete: built again when this view comes back
    state.field = std::move(field);
    std::lock_guard lock(mutex_);
    stats_.vplSeconds = vplSeconds;
    stats_.clusterSeconds = secondsSince(t);
    stats_.vpls = vpls_->vpls.size();
  }
  if (cancelled()) return;
  // In a refining mode the preview only bridges the time until the path-traced film takes over: its
  // passes draw two clusters per pixel, and a pass is begun only if it should end within previewSeconds
  // (one at least), so that refinement starts soon even where a full preview pass takes seconds (a
  // large view of a large scene). Stopping only once previewSeconds had passed let a second 0.75 s
  // pass start at 0.8 s on the interior at 1280x720, and refinement began at 2.77 s instead of 2.0 s.
  // Two clusters chosen at the pixel's own hit beat four chosen by the slice: one pass on the interior
  // at 320x240 had relMSE 0.10-0.15 against 1.4-2.3 (4 seeds), and at 1280x720 refinement started at
  // 2.79 s against 2.84 s (bench/preview_stages, 3 runs).
  const bool refining = request.mode != SamplingMode::Preview;
  PreviewSettings previewSettings = settings_.preview;
  if (refining) previewSettings.clustersPerPass = std::min(previewSettings.clustersPerPass, kBridgingClustersPerPass);
  const PixelShaderFactory previewShading = previewShader(scene, *state.field, previewSettings);
  const int previewTarget = refining ? settings_.previewPasses : settings_.maxSpp;
  const auto previewStart = Clock::now();
  CameraState::ModeFilm& preview = state.preview;
  if (!preview.film) preview.film = std::make_unique<Film>(w, h);
  const TileRenderer previewRenderer(camera, settings_.seed, previewShading, settings_.stratifiedSampler);
  auto modeFilmComplete = [&] {
    auto it = state.films.find(request.mode);
    return it == state.films.end() ? 0 : it->second.complete;
  };
  double lastPassSeconds = 0.0;
  while (preview.complete < previewTarget && modeFilmComplete() < settings_.handoverSpp &&
         !(refining && preview.complete > 0 && secondsSince(previewStart) + lastPassSeconds > settings_.previewSeconds)) {
    const auto passStart = Clock::now();
    previewRenderer.renderPass(*preview.film, preview.nextPass++, &cancel_);
    if (cancelled()) return;
    lastPassSeconds = secondsSince(passStart);
    ++preview.complete;
    publish(preview.film->resolve(), SessionStage::Preview, preview.complete);
    notePreview();
    noteTime();
  }
  if (request.mode == SamplingMode::Preview) return;

  // 3. Refine: the guide for guided modes, then path-traced passes into the mode's own film.
  CameraState::ModeFilm& mine = state.films[request.mode];
  SceneDecisions unkept, &decided = settings_.keepSceneDecisions ? decisions_[request.mode] : unkept;
  if (!mine.film) {
    mine.film = std::make_unique<Film>(w, h);
    if (request.mode == SamplingMode::Mis && settings_.guide.switchToLanes && decided.lanesForMis)
      mine.guideSwitch.adopt(decided.guideGain);
  }
  // mis once BSDF samples in lanes have taken over needs no guide.
  const bool guided = isGuided(request.mode) && !mine.guideSwitch.on();
  if (guided && !state.guide) {
    const auto t = Clock::now();
    state.guide = std::make_unique<GuideField>(buildGuideField(scene, *state.field, settings_.guide));
    std::lock_guard lock(mutex_);
    stats_.guideSeconds = secondsSince(t);
    stats_.cachePoints = state.guide->size();
  }
  if (cancelled()) return;
  ContinuationFactory continuation;
  if (guided) {
    const GuideField& guide = *state.guide;
    const SamplingMode mode = request.mode;
    if (!mine.learners)
      mine.learners = std::make_unique<FilmLearners>(guide, mode, settings_.guide, TileRenderer::tileCountFor(w, h));
    continuation = guidedContinuations(guide, mode, mine.learners->logs());
  }
  const RouletteRule rule = settings_.tracer.roulette;
  // VPL connections: fresh light vertices before every pass, for tracers of this refinement only.
  const int joinPaths = settings_.connections.pathsFor(w * h, request.mode);
  if (joinPaths <= 0) {  // the panel must not show the joins of another mode's film
    std::lock_guard lock(mutex_);
    stats_.joinDepth = SessionStats::kNoJoins;
    stats_.joinDepthTrial = stats_.joinDepthDecided = false;
  }
  // --join-depth auto: an earlier view's depth (SceneDecisions), or the trial. A kept depth 1 waits for
  // this view's relative variance (-1 until read, after kVariancePass); until then the joins are from
  // every vertex, as in the trial's first passes.
  const bool autoJoinDepth = settings_.connections.joinDepth == ConnectionSettings::kJoinDepthAuto;
  const auto chooseJoinDepth = [&](double variance) {
    if (decided.keepsJoinDepth(variance)) {
      mine.joinDepthAdopted = true;
      mine.joins->setJoinDepth(decided.joinDepth);
    } else if (variance >= 0.0 || decided.joinDepth == SceneDecisions::kUndecided) {
      mine.joinTrial = std::make_unique<JoinDepthTrial>(w, h);
    }
  };
  if (joinPaths > 0 && !mine.joins) {
    mine.joins = std::make_unique<LightVertexCache>(settings_.connections);
    if (autoJoinDepth) chooseJoinDepth(-1.0);
  }
  {
    std::lock_guard lock(mutex_);
    stats_.guideSwitchAdopted = mine.guideSwitch.adopted();
    if (mine.guideSwitch.adopted()) stats_.guideGain = mine.guideSwitch.gain();
  }
  if (settings_.tracer.learnLights && !mine.lights) mine.lights = std::make_unique<EmitterGuide>(scene, true);
  const EmitterGuide* lights = mine.lights && mine.lights->active() ? mine.lights.get() : nullptr;
  std::optional<PathTracer> filmTracer, filmWindowTracer;  // with this film's joins or learned lights
  auto refineTracer = [&]() -> const PathTracer& {
    const bool windowed = rule == RouletteRule::Vpl || (rule == RouletteRule::Auto && mine.window.on());
    if (windowed && !windowTracer_) {  // once per scene, when a film first asks for it
      irradiance_ = std::make_unique<IrradianceGrid>(scene, IrradianceGrid::kPhotons, settings_.seed, settings_.tracer.maxDepth);
      PathTracerSettings window = settings_.tracer;
      window.roulette = RouletteRule::Vpl;
      windowTracer_ = std::make_unique<PathTracer>(scene, window, irradiance_.get());
    }
    if (joinPaths <= 0 && !lights) return windowed ? *windowTracer_ : tracer_;
    std::optional<PathTracer>& t = windowed ? filmWindowTracer : filmTracer;
    if (!t)
      t.emplace(scene, windowed ? windowTracer_->settings() : settings_.tracer, windowed ? irradiance_.get() : nullptr,
                joinPaths > 0 ? mine.joins.get() : nullptr, lights);
    return *t;
  };
  std::optional<TileRenderer> renderer;
  std::optional<PathLanes> lanes;  // brdf's, where they apply
  const auto emplaceRenderer = [&] {
    int paths = 1;
    if (isGuided(request.mode) && !mine.guideSwitch.on()) {
      renderer.reset();  // its shader holds the old tracer
      renderer.emplace(camera, settings_.seed, pathTracerShader(refineTracer(), continuation), settings_.stratifiedSampler);
    } else {
      paths = emplaceBsdfRenderer(renderer, lanes, camera, settings_.seed, refineTracer(), settings_.stratifiedSampler);
    }
    std::lock_guard lock(mutex_);
    stats_.lanes = paths;
  };
  emplaceRenderer();
  const auto noteWindow = [&] {
    std::lock_guard lock(mutex_);
    stats_.rouletteWindow = rule == RouletteRule::Vpl || (rule == RouletteRule::Auto && mine.window.on());
  };
  noteWindow();
  // Before the hand-over the film fades in over the preview, in proportion to its samples: the shown
  // image moves towards the path-traced one from the first pass (at 1280x720 door_ajar's mis took 37 s
  // to reach 16 spp, all of it behind a still preview), and no frame steps back to much more noise.
  const Image previewShown = preview.complete > 0 ? preview.film->resolve() : Image();
  const auto publishFilm = [&] {
    Image film = mine.film->resolve();
    const float share = previewShown.pixels.empty() ? 1.0f : float(mine.complete) / float(settings_.handoverSpp);
    const Image shown = crossfade(previewShown, film, share);
    publish(shown, SessionStage::Refine, mine.complete, mine.film->resolveVariance(), share < 1.0f ? std::move(film) : Image());
  };
  // A mode flipped back to shows its own film at once.
  if (mine.complete > 0) publishFilm();
  {
    std::lock_guard lock(mutex_);
    if (stats_.refineStartSeconds == 0.0) stats_.refineStartSeconds = secondsSince(state.restart);
  }
  while (mine.complete < settings_.maxSpp) {
    // The trial counts complete passes, as the roulette's window does, so that it starts after the
    // window's last decision even when a mode switch cancelled a pass; a cancelled trial pass is run again.
    const uint64_t slot = uint64_t(mine.complete);
    const auto t = Clock::now();
    if (mine.lights) mine.lights->learnFromLastPass();
    if (joinPaths > 0) mine.joins->build(scene, settings_.seed, mine.nextPass, joinPaths, settings_.tracer.maxDepth - 1,
                                      settings_.stratifiedSampler, lights);
    const uint64_t index = mine.nextPass++;
    const JoinDepthTrial::PassTargets target = mine.joinTrial ? mine.joinTrial->beginPass(slot, *mine.film, *mine.joins)
                                                             : JoinDepthTrial::PassTargets{*mine.film};
    const PassStats pass = renderer->renderPass(target.film, index, &cancel_, target.counterfactual, target.counterfactualDepth);
    if (mine.joinTrial) {
      mine.joinTrial->endPass(slot, *mine.film, !cancelled(), pass, *mine.joins);
      if (mine.joinTrial->decided()) {
        decided.joinDepth = mine.joinTrial->chosen();
        decided.joinDepthVariance = mine.variance;
      }
    }
    if (mine.joins && autoJoinDepth && !cancelled() && mine.complete + 1 == int(SceneDecisions::kVariancePass)) {
      mine.variance = mine.film->sampleRelativeVariance();
      if (!mine.joinTrial && !mine.joinDepthAdopted) chooseJoinDepth(mine.variance);
    }
    if (mine.joins) {
      std::lock_guard lock(mutex_);
      stats_.joinDepth = mine.joins->joinDepth();
      stats_.joinDepthTrial = mine.joinTrial != nullptr;
      stats_.joinDepthDecided = mine.joinTrial && mine.joinTrial->decided();
      stats_.joinDepthAdopted = mine.joinDepthAdopted;
    }
    state.renderSeconds += secondsSince(t);
    state.samples += pass.samples;
    state.rays += pass.rays;
    {
      std::lock_guard lock(mutex_);
      stats_.discarded += pass.discarded;
      stats_.samplesPerSecond = state.renderSeconds > 0 ? double(state.samples) / state.renderSeconds : 0.0;
      stats_.raysPerSecond = state.renderSeconds > 0 ? double(state.rays) / state.renderSeconds : 0.0;
    }
    if (cancelled()) return;
    ++mine.complete;
    {
      std::lock_guard lock(mutex_);
      stats_.learnedLightRegions = lights ? lights->learnedRegionShare() : -1.0;
    }
    if (mine.learners) {
      mine.learners->update();
      if (request.mode == SamplingMode::Mis && settings_.guide.switchToLanes && !mine.guideSwitch.decided() &&
          mine.guideSwitch.update(uint64_t(mine.complete), mine.learners->guideGain(),
                                  settings_.stratifiedSampler && PathLanes::unsupported(refineTracer()).empty())) {
        decided.lanesForMis = true;
        decided.guideGain = mine.guideSwitch.gain();
        emplaceRenderer();
      }
      std::lock_guard lock(mutex_);
      stats_.learnedBsdfProbability = mine.learners->meanBsdfProbability();
      stats_.learnedGuideShare = mine.learners->meanGuideShare();
      stats_.guideSwitchPass = int(mine.guideSwitch.fromPass());
      stats_.guideGain = mine.guideSwitch.gain();
    }
    if (rule == RouletteRule::Auto && !mine.window.on() && WindowSwitch::updateDue(uint64_t(mine.complete)) &&
        mine.window.update(*mine.film)) {
      emplaceRenderer();
      noteWindow();
    }
    publishFilm();
    noteTime();
  }
}

}  // namespace vpl
