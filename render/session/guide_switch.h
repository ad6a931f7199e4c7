// When mis's guide does not pay for the one-at-a-time paths it needs (`--guide-switch auto`).
//
// The guide's directions are drawn in radiance(), one path at a time; BSDF sampling runs eight paths
// at a time in AVX2 lanes (path_lanes.h), joins and weight window included, at 0.78-0.85x the render
// time of a guided sample on door_ajar and two_rooms (32 spp, 320x240, seeds 1 and 2, on 190c20b; the
// same estimator with --bsdf-prob 1: 0.97-1.02x), and at 0.63-0.70x since (kLanesCostShare). Where the
// guide takes less than that off a sample's variance, the lanes' BSDF samples are the better buy. On
// those scenes it took nothing off: at 32 spp `mis` and `mis --bsdf-prob 1` had the same relMSE within
// the seeds' spread (door_ajar 0.0922 and 0.0923, 0.0901 and 0.0878; two_rooms 0.00785 and 0.00790,
// 0.00794 and 0.00787).
//
// The forecast is the selection learner's (SelectionLearner::guideGain): the second moment of the
// first vertex's continuation with the learned probabilities over that with the BSDF alone. It favours
// the guide (a first vertex's moment is not the pixel's variance, and it leaves out stratification),
// so a gain above kLanesCostShare is a guide that does not pay. Measured at 8 and 32 spp (160x120):
// the Cornell box 0.95, 0.92; door_ajar 0.85, 0.83; two_rooms 0.98, 0.98; the interior 0.93, 0.96; the
// skylit hall and lamp_rooms 1.0 (every cache point learned the BSDF alone); cornell_glossy 0.41,
// 0.39, where the guide keeps its paths.
//
// The decision is made once, after the pass that ends the join depth's trial (whose passes
// radiance() traces anyway), from what the learner has seen by then. Both estimators are unbiased and
// the choice depends only on earlier passes, so the image stays unbiased; it mixes the passes of both.
#pragma once
#include <cstdint>
#include "render/session/join_depth_trial.h"

namespace vpl {

class GuideSwitch {
 public:
  // The lanes' render time per sample over a guided one's, at the same joins (see above). 0.8 when the
  // switch came (190c20b); since the joins in vector form and the lanes' light samples, 0.63-0.70
  // (2026-12-07, 1eb9216, 24 spp, seed 1, render phase of `brdf --connect-paths N --join-depth -1`
  // over `mis --guide-switch off --join-depth -1`: door_ajar 0.65 at 320x240 and 0.63 at 640x360,
  // two_rooms 0.69, the Cornell box 0.70). With 0.8, door_ajar's forecast (0.75 at 640x360) kept the
  // guide there, at 0.55x the lanes' samples in 10 s and 1.8x their relMSE between two seeds.
  static constexpr double kLanesCostShare = 0.67;
  static constexpr uint64_t kDecisionPass = JoinDepthTrial::kLastPass + 1;

  // After `passes` complete passes, with the learner's forecast `guideGain` (-1: none) and whether
  // the lanes can render the film's tracer: true from the pass on which BSDF samples take over.
  bool update(uint64_t passes, double guideGain, bool lanesApply) {
    if (passes == kDecisionPass && !decided_) {
      decided_ = true;
      gain_ = guideGain;
      on_ = lanesApply && guideGain > kLanesCostShare;
      if (on_) fromPass_ = passes;
    }
    return on_;
  }
  // On from the first pass, as an earlier view of the same scene decided with forecast `guideGain`
  // (the viewer keeps the decision across camera moves: ProgressiveSession).
  void adopt(double guideGain) {
    decided_ = on_ = true;
    gain_ = guideGain;
    fromPass_ = 0;
  }
  bool on() const { return on_; }
  // update() turns it on from kDecisionPass, so from pass 0 only by adopt().
  bool adopted() const { return on_ && fromPass_ == 0; }
  bool decided() const { return decided_; }
  double gain() const { return gain_; }
  uint64_t fromPass() const { return fromPass_; }

 private:
  bool on_ = false, decided_ = false;
  double gain_ = -1.0;
  uint64_t fromPass_ = 0;
};

}  // namespace vpl
