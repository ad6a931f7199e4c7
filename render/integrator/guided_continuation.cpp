#include "render/integrator/guided_continuation.h"

#include <algorithm>
#include "render/core/color.h"

namespace vpl {

float GuidedContinuation::bsdfProbability(int c) const {
  switch (mode_) {
    case SamplingMode::Mis: return learner_ ? learner_->bsdfProbability(c) : field_.settings().bsdfProbability;
    case SamplingMode::Metropolis:
    case SamplingMode::Mixture: return 0.0f;
    default: return 1.0f;
  }
}

int GuidedContinuation::cachePoint(const SurfaceHit& hit) {
  if (hit.position != lastPosition_ || hit.shadingNormal != lastNormal_) {
    lastPosition_ = hit.position;
    lastNormal_ = hit.shadingNormal;
    const int maxGuided = field_.settings().guidedVertices;
    if (maxGuided > 0 && vertex_ > maxGuided) {
      lastCachePoint_ = -1;
    } else {
      // The camera ray's hit usually belongs to its pixel's slice: try that cache point first.
      lastCachePoint_ = vertex_ == 1 ? field_.pixelCachePoint(pixel_, hit.position, hit.shadingNormal) : -1;
      if (lastCachePoint_ < 0) lastCachePoint_ = field_.lookup(hit.position, hit.shadingNormal);
    }
  }
  return lastCachePoint_;
}

int GuidedContinuation::servingCachePoint(const SurfaceHit& hit, const Bsdf& bsdf) {
  const int c = cachePoint(hit);  // always asked, so the vertex count stays right
  // A lobe a few degrees wide is found only by sampling it: no tabulated guide can (a mirror under
  // a sky came out 20x too dark in the guide-only modes before this).
  return c < 0 || bsdf.isNearSpecular() ? -1 : c;
}

bool GuidedContinuation::sample(const SurfaceHit& hit, const Bsdf& bsdf, const glm::vec3& wo, VertexSamples& u,
                                DirectionSample& out, PathStats& stats) {
  const int c = servingCachePoint(hit, bsdf);
  const float pBsdf = c < 0 ? 1.0f : bsdfProbability(c);
  // The strategy is the BSDF direction's x, rescaled within the BSDF's share (as Bsdf::sample picks
  // its lobe): the BSDF's directions then stay a stratified set, which a separate strategy number
  // would thin out at random (mis gained 0.54x per sample from the stratified sampler, brdf 0.34x).
  // mis's guide samples (unless they come from the chain) take the rest of the same number, so one
  // stratified point serves the choice and either strategy; mixture's, which have no choice to make,
  // take all of it (a cell from one slot and the point in it from another are not stratified together:
  // per sample at 64 spp on the Cornell box, stratified over random relMSE 0.65 that way, brdf's 0.48).
  const bool shared = (mode_ == SamplingMode::Mis && !field_.settings().misChain) || mode_ == SamplingMode::Mixture;
  glm::vec2 uBsdf = pBsdf > 0.0f || shared ? u.bsdfDirection() : glm::vec2(0.0f);
  if (pBsdf >= 1.0f || uBsdf.x < pBsdf) {
    if (pBsdf < 1.0f) uBsdf.x = std::min(uBsdf.x / pBsdf, 0x1.fffffep-1f);
    const auto s = bsdf.sample(wo, uBsdf);
    if (!s) return false;
    out.wi = s->wi;
    ++stats.bsdfSamples;
    if (pBsdf >= 1.0f) {  // an unguided vertex: the sample's own pdf and weight are the strategy's
      out.pdf = s->pdf;
      out.weight = s->weight;
      if (learnsAt(c)) noteFirstVertex(c, out.wi, {s->pdf, guideAt(c).pdf(out.wi), s->pdf});
      return true;
    }
  } else {
    const GuideDistribution& guide = guideAt(c);
    const bool revisit = std::find(chainsUsedByPath_.begin(), chainsUsedByPath_.end(), c) != chainsUsedByPath_.end();
    // The guide's stratified pair: the rest of the BSDF's number past its share, or all of a fresh one
    // where none was drawn above (the chain's modes, whose BSDF has no share).
    const auto guidePair = [&] {
      return pBsdf > 0.0f || shared ? glm::vec2(std::min((uBsdf.x - pBsdf) / (1.0f - pBsdf), 0x1.fffffep-1f), uBsdf.y)
                                    : u.bsdfDirection();
    };
    if (shared) {
      out.wi = guide.sample(guidePair());
    } else if (mode_ == SamplingMode::Mixture || revisit) {
      out.wi = guide.sample(u.guideCell(), u.guidePoint());
    } else {
      // A Markov chain's states are not stratified samples, but its proposals can be: the first
      // step proposes from the vertex's stratified pair (the rest of it past the BSDF's share), its
      // start, its kind of step and its acceptance use the vertex's random stream.
      chainsUsedByPath_.push_back(c);
      auto it = chains_.find(c);
      if (it == chains_.end()) it = chains_.emplace(c, MetropolisChain(guide, u.random())).first;
      const glm::vec2 point = guidePair();
      ChainStats chain;
      out.wi = it->second.next(guide, field_.settings(), u.random(), chain, &point);
      stats.proposals += chain.proposals;
      stats.accepted += chain.accepted;
    }
    ++stats.guideSamples;
  }
  const Densities d = densities(c, bsdf, wo, out.wi);
  if (learnsAt(c)) noteFirstVertex(c, out.wi, d);
  out.pdf = d.mixture;
  return out.pdf > 0.0f;
}

GuidedContinuation::Densities GuidedContinuation::densities(int c, const Bsdf& bsdf, const glm::vec3& wo,
                                                            const glm::vec3& wi, float bsdfPdf) const {
  const float pBsdf = bsdfProbability(c);
  Densities d;
  d.bsdf = pBsdf > 0.0f ? (bsdfPdf >= 0.0f ? bsdfPdf : bsdf.pdf(wo, wi)) : 0.0f;
  d.guide = pBsdf < 1.0f ? guideAt(c).pdf(wi) : 0.0f;
  d.mixture = pBsdf >= 1.0f ? d.bsdf : pBsdf > 0.0f ? pBsdf * d.bsdf + (1.0f - pBsdf) * d.guide : d.guide;
  return d;
}

float GuidedContinuation::pdf(const SurfaceHit& hit, const Bsdf& bsdf, const glm::vec3& wo, const glm::vec3& wi,
                              float bsdfPdf) {
  const int c = servingCachePoint(hit, bsdf);
  return c < 0 ? bsdfPdf : densities(c, bsdf, wo, wi, bsdfPdf).mixture;
}

void GuidedContinuation::endPath(const glm::vec3& firstContinuation) {
  if (first_.cachePoint < 0) return;
  const Densities& d = first_.densities;
  const float value = std::max(0.0f, luminance(firstContinuation));
  if (log_) log_->add(first_.cachePoint, d.bsdf, d.guide, d.mixture, value);
  if (guideLog_) guideLog_->add(first_.cachePoint, first_.wi, value);
  first_.cachePoint = -1;
}

}  // namespace vpl
