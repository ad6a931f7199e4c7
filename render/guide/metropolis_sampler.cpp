#include "render/guide/metropolis_sampler.h"

#include <cmath>
#include "render/core/frame.h"
#include "render/sampling/warps.h"

namespace vpl {

MetropolisChain::MetropolisChain(const GuideDistribution& distribution, Rng& rng)
    : state_(distribution.sample(rng)), statePdf_(distribution.pdf(state_)) {}

MetropolisChain::MetropolisChain(const GuideDistribution& distribution, const glm::vec3& start)
    : state_(glm::normalize(start)), statePdf_(distribution.pdf(state_)) {}

glm::vec3 MetropolisChain::next(const GuideDistribution& distribution, const GuideSettings& settings, Rng& rng,
                                ChainStats& stats, const glm::vec2* firstPoint) {
  const Cone perturb = Cone::fromAngle(settings.perturbationAngle);
  for (int m = 0; m < settings.mutations; ++m) {
    const float uKind = rng.uniform();
    const glm::vec2 u = m == 0 && firstPoint ? *firstPoint : rng.uniform2();
    // Both proposals are symmetric (q(x -> y) = q(y -> x)), so the acceptance is the pdf ratio.
    const glm::vec3 proposal = uKind < settings.uniformMutation
                                   ? sampleUniformSphere(u)
                                   : glm::normalize(Frame::fromNormal(state_).toWorld(sampleUniformCone(u, perturb)));
    const float proposalPdf = distribution.pdf(proposal);
    ++stats.proposals;
    // The defensive term keeps both pdfs positive, so the ratio is always defined.
    if (rng.uniform() * statePdf_ < proposalPdf) {
      state_ = proposal;
      statePdf_ = proposalPdf;
      ++stats.accepted;
    }
  }
  return state_;
}

}  // namespace vpl
