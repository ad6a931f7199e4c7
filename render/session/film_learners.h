// What one film's passes teach its guided continuations: mis's BSDF probability per cache point
// (--bsdf-prob auto) and the guides (--guide-learning on), each only when the settings ask for it.
// The CLI's render job and the viewer's session keep one per film, hand its logs to every pass
// and update it between passes.
#pragma once
#include <optional>
#include "render/guide/guide_learner.h"
#include "render/guide/guide_settings.h"
#include "render/guide/selection_learner.h"
#include "render/integrator/sampling_mode.h"

namespace vpl {

class FilmLearners {
 public:
  // `guide` holds the priors and must outlive the learners.
  FilmLearners(const GuideField& guide, SamplingMode mode, const GuideSettings& settings, int tiles) {
    if (mode == SamplingMode::Mis && settings.learnSelection) selection_.emplace(guide.size(), tiles, settings.bsdfProbability);
    if (settings.learnDirections) guides_.emplace(guide, tiles, settings.vplPrior, learnedDefensive(mode, settings));
  }

  // The uniform share of the learned guides: mis's own where its BSDF probability, fixed or the learned
  // one's start, is at least the least the learner can choose (SelectionLearner::kCandidates), so that
  // it never falls below that; else the guide-only modes' (GuideSettings::defensive).
  static float learnedDefensive(SamplingMode mode, const GuideSettings& settings) {
    const float least = SelectionLearner::kCandidates.front();
    return mode == SamplingMode::Mis && settings.bsdfProbability >= least ? settings.misDefensive : settings.defensive;
  }

  // The learners that a pass's continuations write to (absent ones as nullptr).
  GuideLearners logs() { return {selection_ ? &*selection_ : nullptr, guides_ ? &*guides_ : nullptr}; }
  // Only between passes, when no tile is being rendered.
  void update() {
    if (selection_) selection_->update();
    if (guides_) guides_->update();
  }
  // For the JSON line and the viewer's panel; -1 for a learner that is off.
  double meanBsdfProbability() const { return selection_ ? selection_->meanLearnedProbability() : -1.0; }
  double guideGain() const { return selection_ ? selection_->guideGain() : -1.0; }
  double meanGuideShare() const { return guides_ ? guides_->meanLearnedShare() : -1.0; }

 private:
  std::optional<SelectionLearner> selection_;
  std::optional<GuideLearner> guides_;
};

}  // namespace vpl
