// What a view's first passes measure about the scene rather than the view, which the viewer's session
// keeps across camera moves (ProgressiveSession): a later view starts from it instead of spending its
// first passes on the measurement again. At 1280x720 on the Cornell box those passes (mis's guided
// paths one at a time until the guide switch, the join depth trial's passes through the scalar tracer)
// took twice a later pass's time.
//
// A kept decision only changes which unbiased estimator a pass uses, so every view stays unbiased;
// what a wrong one costs is efficiency:
// - mis's guide switch (BSDF samples in lanes) once it turned on. Its forecast, what the guide takes
//   off the first vertex's second moment, follows the scene's light more than the view: on the scenes
//   the lanes serve the joins take off most of what the guide would (guide_switch.h: it turned on on
//   each of them). Where it stayed off, the next view measures again. A keep that is wrong for a view
//   costs that view what the guide would have taken off; not measured.
// - the join depth trial's every vertex: the trial's own fallback; where depth 1 won, it had 0.86-0.98
//   of every vertex's relMSE x time (the skylit hall, the Cornell box, lamp_rooms).
// - its depth 1 only while the new view's samples vary about as little as the deciding view's did:
//   depth 1 wins where the lights are found directly, and loses 2-4x per sample where light comes
//   through a slit (door_ajar), where samples vary 30x more (Film::sampleRelativeVariance: the Cornell
//   box 0.03-0.07, two_rooms 0.5, door_ajar 1.5-2.2). A view whose samples vary more than
//   kSimilarVariance times as much runs the trial again.
#pragma once
#include <cstdint>

namespace vpl {

struct SceneDecisions {
  static constexpr int kUndecided = -100;
  // The complete passes after which a view's relative variance per sample is read (WindowSwitch
  // reads it then too), before the trial prepares (JoinDepthTrial::kFirstPass - 1).
  static constexpr uint64_t kVariancePass = 2;
  static constexpr double kSimilarVariance = 2.0;

  bool lanesForMis = false;  // mis's guide switch turned on, with this forecast
  double guideGain = -1.0;
  int joinDepth = kUndecided;     // the join depth trial's choice (JoinDepthTrial::kCandidates)
  double joinDepthVariance = 0.0;  // the deciding view's relative variance per sample after kVariancePass

  // Whether a new view keeps the chosen join depth without a trial: every vertex always, depth 1 when
  // its samples after kVariancePass vary as little as above (`variance` < 0: not read yet).
  bool keepsJoinDepth(double variance) const {
    if (joinDepth == -1) return true;
    return joinDepth == 1 && variance >= 0.0 && variance <= kSimilarVariance * joinDepthVariance;
  }
};

}  // namespace vpl
