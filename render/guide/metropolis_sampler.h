// A Markov chain over directions whose stationary density is a cache point's guide pdf (Hua & Low
// 2015; DESIGN.md §2 step 7). Two symmetric proposals: an independent uniform direction, or a
// uniform perturbation within a small cone around the current state; acceptance min(1, p(y)/p(x)).
// The chain starts from an exact sample of the pdf, so every state it returns is distributed by the
// pdf itself: dividing by pdf() keeps the path tracer unbiased.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>
#include "render/guide/guide_distribution.h"
#include "render/guide/guide_settings.h"

namespace vpl {

struct ChainStats {
  uint64_t proposals = 0, accepted = 0;
};

class MetropolisChain {
 public:
  MetropolisChain() = default;
  // Starts at an exact sample of the distribution.
  MetropolisChain(const GuideDistribution& distribution, Rng& rng);
  // Starts at a given unit direction, which is not a sample of the pdf: for tests of how the chain
  // forgets its start.
  MetropolisChain(const GuideDistribution& distribution, const glm::vec3& start);

  // Runs `settings.mutations` steps and returns the new state. `firstPoint`, when given, is the first
  // step's proposal point in place of two numbers of rng: a pixel's stratified pair, as the other
  // strategies' directions take it. Each pixel scrambles its own, so to the chain it is one more
  // uniform pair independent of its state, and the steps keep the guide's pdf.
  glm::vec3 next(const GuideDistribution& distribution, const GuideSettings& settings, Rng& rng, ChainStats& stats,
                 const glm::vec2* firstPoint = nullptr);

  glm::vec3 state() const { return state_; }

 private:
  glm::vec3 state_{0, 0, 1};
  float statePdf_ = 0.0f;
};

}  // namespace vpl
