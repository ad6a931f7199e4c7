// `--join-depth auto`: the render measures which join depth pays on this scene and keeps it.
//
// Joins from every camera vertex are what make light through a slit cheap (door_ajar, two_rooms),
// but where the lights are found directly they cost more than they bring: at equal time (10 s) the
// Cornell box has 0.84x the relMSE with joins only up to depth 1, where door_ajar has 1.45x. The
// trade is a property of the scene, so each candidate depth renders a few whole passes, interleaved
// after the auto roulette's window has decided, and the depth of least variance x time wins for
// the rest of the render. The trial's passes of the losing depth stay in the image, so it must be
// short: two candidates, two passes each (-1, 1, 1, -1). Depth 0 is not one: on the Cornell box it is about as
// good as depth 1 (1-spp relMSE x cost 0.099 against 0.096), and on door_ajar and two_rooms its
// trial passes, 4x worse per sample than every vertex's, cost more than a choice could win (a trial
// of three depths, three passes each, at 22 spp in 10 s: two_rooms 1.4x the relMSE of every vertex).
// Nor is depth 2: two passes rarely show its rare bright samples, so it won the trial on two_rooms
// where it loses (32 spp, 3 seeds: 1.26x the relMSE at 0.9x the time).
//
// The trial's passes count for half as much as the others in the image (kTrialPassWeight), the same
// for both candidates and fixed before any of them ran, so the image stays unbiased while the losing
// depth's passes, up to 2-4x worse per sample on door_ajar, add a quarter of their variance.
//
// Every pass is an unbiased estimate whatever its depth (the MIS weights leave out exactly the
// joins a depth forbids), and the choice depends only on earlier passes, so the image stays
// unbiased. A candidate's cost is the rays its passes traced (the light paths' included), not their
// seconds: the time of a pass follows its rays (2.03x the render phase for 2.02x the rays, mis
// against brdf on the Cornell box), and rays keep the choice, and so the image, deterministic in the
// seed whatever the machine's load or the thread count.
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

class JoinDepthTrial {
 public:
  static constexpr std::array<int, 2> kCandidates = {-1, 1};  // -1: every vertex, the fallback
  static constexpr int kPassesEach = 2;
  // The trial starts after the auto roulette's last decision (WindowSwitch::updateDue), so that every
  // candidate is timed with the tracer that the rest of the render uses.
  static constexpr uint64_t kFirstPass = 4;
  static constexpr uint64_t kLastPass = kFirstPass + kCandidates.size() * kPassesEach - 1;
  // What a trial pass's samples weigh in the image, against 1 for any other pass.
  static constexpr double kTrialPassWeight = 0.5;

  JoinDepthTrial(int width, int height);

  // What a render loop calls around pass `slot` (counting complete passes), after the pass's light
  // vertices are built: sets the depth the joins use and returns the film to render into, the image
  // itself or, during a prepared trial (endPass), a film of the pass's own.
  Film& beginPass(uint64_t slot, Film& image, LightVertexCache& joins);
  // After the pass: a complete trial pass is recorded with the rays it traced, the camera paths'
  // and the light paths' that `joins` built for it (a depth's cost is the whole pass's), and its
  // samples join the image either way, weighing kTrialPassWeight. The complete pass before the trial
  // prepares it (start() and the pass film).
  void endPass(uint64_t slot, Film& image, bool complete, double cameraRays, const LightVertexCache& joins);

  // Before the first trial pass: the image so far, whose luminance weighs the pixels.
  void start(const Film& film);
  // Whether pass `pass` (0-based) is one of the trial's (beginPass/endPass route it).
  static bool isTrialPass(uint64_t pass) { return pass >= kFirstPass && pass <= kLastPass; }
  // The depth pass `pass` joins to: the candidates in turn during the trial, the winner after it,
  // every vertex before it.
  int depthFor(uint64_t pass) const;
  // The same, for the pass about to start: past the trial, decides from what was recorded if the
  // last trial pass was never recorded (a test or caller that skipped it).
  int depthForNext(uint64_t pass) {
    if (pass > kLastPass && !decided_) decide();
    return depthFor(pass);
  }
  // A complete trial pass's own film (one sample per pixel) and its rays. The last one decides.
  void record(uint64_t pass, const Film& passFilm, double rays);

  bool decided() const { return decided_; }
  int chosen() const { return chosen_; }
  // Per candidate: relative variance per pass times rays per pass (0 before the decision).
  const std::array<double, kCandidates.size()>& scores() const { return scores_; }

 private:
  // In the order -1, 1, 1, -1: each candidate's mean pass sits at the trial's middle, so the guides and
  // join choices, which learn between passes, favour neither.
  static size_t candidateOf(uint64_t pass) {
    static_assert(kCandidates.size() == 2 && kPassesEach == 2);
    const size_t i = size_t(pass - kFirstPass);
    return i == 1 || i == 2 ? 1 : 0;
  }
  void decide();

  // The variance is a median of means over groups of rows: one rare bright sample in one pixel (a
  // Cornell box's trial pass had one that tripled a candidate's sum) must not decide.
  static constexpr size_t kGroups = 9;

  size_t width_, pixels_;
  std::optional<Film> passFilm_;  // a trial pass's own samples, freed once the trial has decided
  std::vector<double> weight_;  // per pixel: 1 / (m^2 + 0.01), m from start()
  // Per candidate and pixel: the sum and sum of squares of the passes' luminance.
  std::array<std::vector<double>, kCandidates.size()> sum_, sum2_;
  std::array<double, kCandidates.size()> rays_{}, scores_{};
  std::array<int, kCandidates.size()> passes_{};
  bool decided_ = false;
  int chosen_ = -1;
};

}  // namespace vpl
