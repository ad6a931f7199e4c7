// The options shared by the headless commands (render, bench, capture, ...), bound to CLI11.
#pragma once
#include <string>
#include <CLI/CLI.hpp>
#include "render/session/render_job.h"

namespace vpl::app {

struct RenderOptions {
  std::string scene;
  std::string mode = "brdf";
  int spp = 0;
  double time = 0.0;
  int width = 640, height = 480;
  uint64_t seed = 1;
  int threads = 0;  // 0 = all cores
  std::string roulette = "auto";
  std::string sampler = "sobol";
  std::string bsdfProb = "auto";  // mis: "auto" (learned per cache point) or a fixed probability
  std::string misGuide = "exact";  // mis: exact stratified guide samples, or the Metropolis chain
  PathTracerSettings tracer;  // depth, roulette start and the weight window's flags (the rule: `roulette`)
  ConnectionSettings connections;  // --connect-paths
  std::string out, png;
  std::string sky;  // "R,G,B", "0", or empty (automatic)
  float exposure = 0.0f;
  double rawSeconds = 3.0;  // bench only
  PreviewSettings preview;  // VPL, slice and cluster flags
  int sliceSize = 0;        // --slice-size; 0: the mode's default (kGuidedSliceSize or the preview's)
  GuideSettings guide;
  float coneDegrees = 20.4f, perturbDegrees = 9.0f;

  void addTo(CLI::App& command, bool requireOut);  // a headless command: scene, budget, outputs, the rest
  void addViewerOptionsTo(CLI::App& app);           // the viewer: an optional scene and the rest
  void addConvergeTo(CLI::App& command);            // converge: a scene and the rest (budgets and size come with it)
  // Checked conversion; throws InputError for values CLI11 cannot check alone.
  RenderJobSettings toSettings() const;
  int threadCount() const;

 private:
  void addCommonTo(CLI::App& command);  // mode, size, seed, threads, depth, sky, exposure, VPL and guide flags
};

// Largest slice (cache point) of the guided modes' renders when --slice-size is not given. Measured
// (320x240, 2 seeds, 32 spp): the same mis relMSE as 256 on four scenes (within 2 %) for 0.16-0.23 s of
// preprocessing instead of 0.26-0.35 s. The preview keeps 256: at 512 its relMSE rose 1.2-1.6x on
// two_rooms and the interior.
inline constexpr int kGuidedSliceSize = 512;

// Throws InputError when a file cannot be created at path (missing folder, no permission), or when
// its name says another image format than the one written there (`format`: "exr" or "png"; a name
// with no image extension is the user's choice).
void checkWritable(const std::string& path, const char* format = nullptr);

}  // namespace vpl::app
