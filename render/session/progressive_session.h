// The progressive render loop the viewer drives (DESIGN.md §2 step 9). One controller thread runs
// the passes on a TBB arena of `threads` workers; the UI thread only posts changes (camera, mode,
// size) and picks up the newest image, so it never waits for a pass. After every restart:
//   1. quick     a 1-spp BSDF pass at a quarter of the resolution: a whole new frame at once
//   2. preview   first one pass of a coarse preview (few slices, few clusters per pixel: fast), then
//                this camera's gather points, slices and LightSlice clusters in full (the VPLs themselves
//                are traced once per scene and kept), then preview passes (in a refining mode at most
//                `previewPasses` and `previewSeconds`, with fewer clusters per pixel)
//   3. refine    the guide (guided modes), then path-traced passes into the mode's own film, until
//                `maxSpp`
// The shown image is the newest stage with something to show; the path-traced film fades in over the
// preview from its first pass and has taken over at `handoverSpp` samples, so the picture is never
// black, never steps back to much more noise and never waits behind a still preview. Films are kept
// per mode while the camera stays, so flipping back to a mode shows its image at once. What a view's
// first passes measure about the scene rather than the view (SceneDecisions) is kept across camera
// moves, so that a later view need not spend its first passes on it again.
#pragma once
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include "render/film/image.h"
#include "render/guide/guide_settings.h"
#include "render/integrator/light_vertex_cache.h"
#include "render/integrator/path_tracer.h"
#include "render/integrator/sampling_mode.h"
#include "render/scene/camera.h"
#include "render/scene/render_scene.h"
#include "render/session/scene_decisions.h"
#include "render/vpl/irradiance_grid.h"
#include "render/vpl/vpl_preview.h"

namespace vpl {

struct SessionSettings {
  SamplingMode mode = SamplingMode::Mis;
  int width = 640, height = 480;
  uint64_t seed = 1;
  int threads = 0;           // render workers; 0: every core
  int previewPasses = 4;      // refining modes: preview passes at most (fewer clusters per pixel than `preview` mode)
  double previewSeconds = 1.0;  // refining modes: ... and a pass begun only if it should end by then (one at least)
  int handoverSpp = 16;      // path-traced samples at which the display has left the preview (a fade until then)
  int maxSpp = 1 << 16;      // the controller idles after this many path-traced samples
  int maxSlices = 384;       // slices (cache points) per view at most; 0: preview.slices alone decides
  bool coarsePreview = true;  // show a coarse preview pass before the full clustering
  // Keep what a view's passes decided about the scene across camera moves (SceneDecisions); false: every view
  // measures again, as a fresh session would (the ablation of bench/refine_after_move).
  bool keepSceneDecisions = true;
  // The camera paths' numbers: stratified (Owen-scrambled Sobol'), or independent random in every
  // pass, quick, preview and refining alike (`--sampler random`, an ablation; RenderJobSettings's).
  bool stratifiedSampler = true;
  PathTracerSettings tracer;
  ConnectionSettings connections;  // VPL connections of the refining passes
  PreviewSettings preview;
  GuideSettings guide;
};

enum class SessionStage { Quick, Coarse, Preview, Refine, Done };  // Coarse: the coarse preview pass
const char* stageName(SessionStage stage);

struct SessionStats {
  SessionStage stage = SessionStage::Quick;  // of the image shown
  SamplingMode mode = SamplingMode::Mis;
  int spp = 0;                   // samples per pixel of the image shown (preview: passes)
  double sinceRestart = 0.0;     // seconds since the last restart
  double firstFrameSeconds = 0.0;  // restart -> first full frame (the quick pass)
  double firstPreviewSeconds = 0.0;  // restart -> first preview image (coarse or full); 0 until then
  double refineStartSeconds = 0.0;   // restart -> the first path-traced pass begins; 0 until then
  double samplesPerSecond = 0.0, raysPerSecond = 0.0;  // of the path-traced passes so far
  double vplSeconds = 0.0, clusterSeconds = 0.0, guideSeconds = 0.0;
  size_t vpls = 0, cachePoints = 0;
  uint64_t discarded = 0;
  uint64_t restarts = 0;
  bool rouletteWindow = false;  // the film shown uses the VPL weight window (--roulette vpl, or auto switched)
  double learnedBsdfProbability = -1.0;  // mis: mean learned BSDF probability over cache points (-1: none yet)
  int guideSwitchPass = 0;   // mis: the pass from which BSDF samples in lanes took over (0: not, or not yet)
  int lanes = 1;             // paths the refinement traces at once (PathLanes::kLanes where the lanes apply)
  double guideGain = -1.0;   // mis: the forecast that decided it (GuideSwitch), -1 until decided
  bool guideSwitchAdopted = false;  // mis: BSDF samples in lanes from the first pass, as an earlier view decided
  double learnedGuideShare = -1.0;       // learned guides: mean weight of the learned part against the prior (-1: off)
  double learnedLightRegions = -1.0;     // learned next-event estimation: the share of regions that learned (-1: off)
  static constexpr int kNoJoins = -100;
  int joinDepth = kNoJoins;               // VPL connections: the depth the last pass joined to (-1: every vertex)
  bool joinDepthTrial = false, joinDepthDecided = false;  // --join-depth auto: trying, or decided
  bool joinDepthAdopted = false;  // --join-depth auto: the depth an earlier view's trial chose, without a trial
};

class ProgressiveSession {
 public:
  ProgressiveSession(std::shared_ptr<const RenderScene> scene, const CameraData& camera, const SessionSettings& settings);
  ~ProgressiveSession();  // cancels the pass under way and joins every thread
  ProgressiveSession(const ProgressiveSession&) = delete;
  ProgressiveSession& operator=(const ProgressiveSession&) = delete;

  // Each of these cancels the pass under way; the controller restarts at once.
  void setCamera(const CameraData& camera);
  void setMode(SamplingMode mode);
  void resize(int width, int height);  // sizes below 1 are ignored (a minimised window)

  // Copies the newest image into `out` when it is newer than `version` (then updated); else false.
  // `variance`, when given, gets the per-pixel relative variance of the path-traced estimate (its
  // error, DESIGN.md §4, as the samples themselves predict it); zeros while the preview is shown.
  bool latestImage(Image& out, uint64_t& version, Image* variance = nullptr) const;
  // What the shown stage has estimated, without the display's fade: once a refining pass is in, the
  // path-traced film alone (the image the samples converge to), before it the quick pass or the
  // preview. "save EXR" writes this; a screenshot, what the window shows.
  struct Estimate {
    Image image;
    SessionStage stage = SessionStage::Quick;
    int spp = 0;
  };
  Estimate latestEstimate() const;
  SessionStats stats() const;
  const SessionSettings& settings() const { return settings_; }
  CameraData camera() const;
  // Blocks until the controller is idle (maxSpp reached) or `seconds` pass; true when idle. For tests
  // and scripted captures.
  bool waitUntilDone(double seconds) const;

 private:
  struct Request;
  struct CameraState;
  void requestRestart();  // with mutex_ held: post the current camera, mode and size, cancel the pass
  void controllerLoop();
  void runUntilChanged(CameraState& state, const Request& request);
  // `estimate`: the stage's own image when `image` is a display mix (the fade); empty: `image` is it.
  void publish(const Image& image, SessionStage stage, int spp, Image variance = {}, Image estimate = {});
  bool cancelled() const { return cancel_.load(std::memory_order_relaxed); }

  std::shared_ptr<const RenderScene> scene_;
  SessionSettings settings_;  // width and height change under mutex_; the rest is fixed
  PathTracer tracer_;                   // the quick frames' (and, without the vpl rule, every pass's)
  std::shared_ptr<const VplSet> vpls_;  // traced once per scene; only the controller touches it
  // The vpl roulette rule's estimate and the tracer that uses it, made once per scene when a film
  // first uses the rule (at once with --roulette vpl, on the film's variance with auto).
  std::unique_ptr<IrradianceGrid> irradiance_;
  std::unique_ptr<PathTracer> windowTracer_;
  // Per mode, what an earlier view decided about the scene; only the controller touches it.
  std::map<SamplingMode, SceneDecisions> decisions_;

  mutable std::mutex mutex_;  // guards everything below up to the thread
  mutable std::condition_variable changed_;
  std::unique_ptr<Request> pending_;
  bool quit_ = false, idle_ = false;
  Image shown_, shownVariance_, estimate_;
  uint64_t version_ = 0;
  SessionStats stats_;
  CameraData camera_;

  std::atomic<bool> cancel_{false};
  std::thread controller_;
};

}  // namespace vpl
