// `--join-depth auto`: the render measures which join depth pays on this scene and keeps it.
//
// Joins from every camera vertex are what make light through a slit cheap (door_ajar, two_rooms),
// but where the lights are found directly they cost more than they bring: on the skylit hall joins
// only up to depth 1 have 0.86x the relMSE of every vertex's at equal time (10 s, 3 seeds). The trade is
// a property of the scene, so a few passes measure both and the depth of least variance x rays wins
// for the rest of the render.
//
// The trial's passes join at every vertex, as any other pass before the decision, and the tracer
// weighs each of their samples a second time as depth 1's joins would have (PathTracer::radiance's
// counterfactual: joins change only the MIS weights and add shadow rays, never the camera path), so
// both candidates are measured on the same paths and no pass of the losing depth reaches the image.
// An earlier trial rendered two passes of each depth instead and kept all four in the image at half
// weight: depth 1's passes, up to 2-4x worse per sample on door_ajar, cost 2 % of the relMSE on
// door_ajar and two_rooms at 60 s where every vertex won.
// Depth 0 is not a candidate: on the Cornell box it is about as good as depth 1 (1-spp relMSE x cost
// 0.099 against 0.096), and 4x worse per sample than every vertex's on door_ajar and two_rooms. Nor is
// depth 2, whose rare bright samples a few passes rarely show (it won a trial on two_rooms where it
// loses: 32 spp, 3 seeds, 1.26x the relMSE at 0.9x the time).
//
// Every pass is an unbiased estimate whatever its depth (the MIS weights leave out exactly the
// joins a depth forbids), and the choice depends only on earlier passes, so the image stays
// unbiased. A candidate's cost is the rays its passes traced or would have (the light paths'
// included), not their seconds: the time of a pass follows its rays (2.03x the render phase for
// 2.02x the rays, mis against brdf on the Cornell box), and rays keep the choice, and so the image,
// deterministic in the seed whatever the machine's load or the thread count.
//
// The measure, per candidate: the mean over pixels of its passes' sample variance of luminance,
// each pixel weighted by 1 / (m^2 + 0.01), m the image of the passes before the trial (relMSE's
// weights, DESIGN.md §4, with that image in place of the reference), taken as the median over nine
// interleaved groups of rows, times the candidate's mean rays per pass, its light paths' included.
// The weights must not come from the trial's own passes: a candidate's rare bright sample would
// raise its pixel's mean and so hide its own variance (door_ajar then chose depth 0, which has 4x
// the relMSE of every vertex there at 16 spp).
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <vector>
#include "render/film/film.h"

namespace vpl {

class LightVertexCache;
struct PassStats;

class JoinDepthTrial {
 public:
  // -1: every vertex, what the trial's passes trace and the fallback; 1: the counterfactual.
  static constexpr std::array<int, 2> kCandidates = {-1, 1};
  static constexpr int kTrialPasses = 4;
  // The trial starts after the auto roulette's last decision (WindowSwitch::updateDue), so that every
  // candidate is measured with the tracer that the rest of the render uses.
  static constexpr uint64_t kFirstPass = 4;
  static constexpr uint64_t kLastPass = kFirstPass + kTrialPasses - 1;
  // Depth 1 wins only with a score below this share of every vertex's: the trial's forecast favours it.
  // Its samples' variance leaves out what the stratified sampler takes off each candidate's error
  // over many passes, which is more for every vertex's joins (Cornell box, 64 spp: depth 1 has 1.05x
  // every vertex's relMSE with independent numbers, 1.10x stratified), and rays leave out that a
  // join's ray is cheaper than a camera vertex's work (cornell_glossy: 0.83x the rays took 0.88x the
  // time). Measured at 64 spp against the forecasts of 24-spp renders (seeds 1, 2), depth 1's relMSE x
  // render time over every vertex's: Cornell box 0.95 (forecast 0.85, 0.86), lamp_rooms 0.91
  // (0.74, 0.75), skylit hall 0.98 (0.86, 0.87), cornell_glossy 1.05 (0.89, 0.93): 0.88 keeps the
  // three that win and leaves the one that loses.
  static constexpr double kForecastMargin = 0.88;

  JoinDepthTrial(int width, int height);

  // Where a pass renders: its samples, and what depth 1's would have been (null outside the trial).
  struct PassTargets {
    Film& film;
    Film* counterfactual = nullptr;
    int counterfactualDepth = kCandidates[1];
  };
  // What a render loop calls around pass `slot` (counting complete passes), after the pass's light
  // vertices are built: sets the depth the joins use and returns the films to render into: the image
  // itself or, during a prepared trial (endPass), a film of the pass's own and the counterfactual's.
  PassTargets beginPass(uint64_t slot, Film& image, LightVertexCache& joins);
  // After the pass: a complete trial pass is recorded with the rays it traced (`stats`, and the light
  // paths' that `joins` built for it) and the rays depth 1 would have traced; its samples join the
  // image either way. The complete pass before the trial prepares it (start() and the films).
  void endPass(uint64_t slot, Film& image, bool complete, const PassStats& stats, const LightVertexCache& joins);

  // Before the first trial pass: the image so far, whose luminance weighs the pixels.
  void start(const Film& film);
  // Whether pass `pass` (0-based) is one of the trial's (beginPass/endPass route it).
  static bool isTrialPass(uint64_t pass) { return pass >= kFirstPass && pass <= kLastPass; }
  // The depth pass `pass` joins to: every vertex until the trial has decided, the winner after it.
  int depthFor(uint64_t) const { return decided_ ? chosen_ : kCandidates[0]; }
  // The same, for the pass about to start: past the trial, decides from what was recorded if the
  // last trial pass was never recorded (a test or caller that skipped it).
  int depthForNext(uint64_t pass) {
    if (pass > kLastPass && !decided_) decide();
    return depthFor(pass);
  }
  // A complete trial pass: per candidate, its film (one sample per pixel) and the rays it traced or
  // would have. The last one decides.
  void record(uint64_t pass, const std::array<const Film*, kCandidates.size()>& films,
              const std::array<double, kCandidates.size()>& rays);

  bool decided() const { return decided_; }
  int chosen() const { return chosen_; }
  // Per candidate: relative variance per pass times rays per pass (0 before the decision).
  const std::array<double, kCandidates.size()>& scores() const { return scores_; }

 private:
  void decide();

  // The variance is a median of means over groups of rows: one rare bright sample in one pixel (a
  // Cornell box's trial pass had one that tripled a candidate's sum) must not decide.
  static constexpr size_t kGroups = 9;

  size_t width_, pixels_;
  // A trial pass's own samples and depth 1's, freed once the trial has decided.
  std::optional<Film> passFilm_, counterfactualFilm_;
  std::vector<glm::vec3> weight_;  // per pixel and channel: 1 / (m^2 + 0.01), m from start()
  // Per candidate, pixel and channel: the sum and sum of squares of the passes' samples (floats: a
  // trial's few passes lose nothing that matters to a ratio of variances, and a large window's pixels
  // keep the memory down).
  std::array<std::vector<glm::vec3>, kCandidates.size()> sum_, sum2_;
  std::array<double, kCandidates.size()> rays_{}, scores_{};
  int passes_ = 0;
  bool decided_ = false;
  int chosen_ = -1;
};

}  // namespace vpl
