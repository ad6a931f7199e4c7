// A complete headless render: load, build, (guide,) render to a spp or time budget. The CLI's
// `render`, `bench` and `converge` commands and the end-to-end tests all go through here.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>
#include "render/film/image.h"
#include "render/integrator/light_vertex_cache.h"
#include "render/integrator/path_tracer.h"
#include "render/integrator/sampling_mode.h"
#include "render/scene/render_scene.h"
#include "render/guide/guide_settings.h"
#include "render/vpl/vpl_preview.h"

namespace vpl {

struct RenderJobSettings {
  std::string scenePath;
  SamplingMode mode = SamplingMode::Brdf;
  int width = 640, height = 480;
  uint64_t seed = 1;
  int spp = 16;               // used when timeBudget <= 0
  double timeBudget = 0.0;    // seconds after load (BVH, VPLs, clustering and rendering all count)
  PathTracerSettings tracer;
  ConnectionSettings connections;  // VPL connections (path-tracing modes)
  PreviewSettings preview;  // VPLs, slices and clusters (preview and guided modes)
  GuideSettings guide;      // guided modes
  SkySettings sky;
  // The camera paths' numbers: the stratified sampler (Owen-scrambled Sobol'), or independent random
  // numbers at every slot (false; the paper's setting, an ablation).
  bool stratifiedSampler = true;

  std::string validate() const;  // empty when valid
};

struct PhaseTimings {
  double load = 0, bvh = 0, vpl = 0, cluster = 0, render = 0;
  double irradiance = 0;  // the VPL roulette's irradiance grid
  double connections = 0;  // light paths for VPL connections, all passes
  // cluster's parts: gather points, slice tree, LightSlice (reduced matrix, global clusters, per-slice
  // refinement) and, in the guided modes, the guide
  double gather = 0, slices = 0, matrix = 0, globalClusters = 0, refine = 0, guide = 0;
  double guideLearning = 0;  // the learners' updates between passes, guides and mis's probability (part of render)
};

struct RenderJobResult {
  Image image;
  int spp = 0;                 // complete passes
  double seconds = 0.0;        // wall time after load
  double firstImageSeconds = 0.0;
  PhaseTimings timings;
  uint64_t rays = 0, samples = 0, discarded = 0, bsdfSamples = 0, guideSamples = 0;
  size_t triangles = 0;
  size_t vplCount = 0, sliceCount = 0;
  double clustersPerSlice = 0.0;
  uint64_t proposals = 0, accepted = 0;  // Metropolis mutations
  uint64_t branches = 0;                 // extra paths grown by splitting (the vpl roulette rule)
  int windowFromPass = 0;                // the auto rule: the window's first pass (0: never used)
  std::optional<int> joinDepthChosen;    // --join-depth auto: the trial's choice, once made
  std::vector<double> joinDepthScores;   // its score per candidate (JoinDepthTrial::kCandidates)
  int connectionPaths = 0;               // VPL connections: light paths per pass (0: none)
  double learnedBsdfProbability = -1.0;  // mis: the mean learned BSDF probability over cache points (-1: none)
  double guideGain = -1.0;  // mis: SelectionLearner::guideGain at the end (-1: none)
  int guideSwitchPass = 0;  // mis: the pass from which BSDF samples in lanes took over (0: never; guide_switch.h)
  double learnedLightRegions = -1.0;     // learned next-event estimation: the share of regions that learned (-1: off)
  int lanes = 1;                         // paths traced at once: PathLanes::kLanes where the lanes applied, else 1
  double learnedGuideShare = -1.0;       // learned guides: the mean weight of what was learned against the VPLs
  size_t guideBytes = 0;
  std::vector<std::string> notices;
};

// progress(fraction in [0,1]) is called after every pass.
RenderJobResult runRenderJob(const RenderJobSettings& settings,
                             const std::function<void(double)>& progress = nullptr);
// The same on a scene already in memory (settings.scenePath is then only a name).
RenderJobResult runRenderJob(const RenderJobSettings& settings, SceneData data,
                             const std::function<void(double)>& progress = nullptr);

}  // namespace vpl
