// Continuation directions from the VPL guide (DESIGN.md §2 step 8):
//   metropolis  the cache point's Markov chain alone
//   mixture     exact samples of the same target (representative by weight, then its cone)
//   mis         one-sample MIS of the BSDF and the Markov chain, balance heuristic with both pdfs
// A vertex with no cache point nearby (distance or normal test), or with a near-specular BSDF,
// samples its BSDF. mis's BSDF probability is the settings' own, or with a SelectionLearner each
// cache point's learned one; the guide is the VPLs', or with a GuideLearner the one learned from the
// film's earlier passes. The first vertex of every path reports to the tile's logs of the learners.
// One object per tile and pass: its chains restart from exact samples, so results do not depend on
// scheduling.
#pragma once
#include <unordered_map>
#include "render/guide/guide_field.h"
#include "render/guide/metropolis_sampler.h"
#include "render/guide/guide_learner.h"
#include "render/integrator/path_tracer.h"
#include "render/integrator/sampling_mode.h"

namespace vpl {

class GuidedContinuation final : public ContinuationSampler {
 public:
  GuidedContinuation(const GuideField& field, SamplingMode mode, GuideLearners learners = {}, uint32_t tile = 0)
      : field_(field), mode_(mode), learner_(learners.selection),
        log_(learners.selection ? &learners.selection->tileLog(tile) : nullptr), guides_(learners.directions),
        guideLog_(learners.directions ? &learners.directions->tileLog(tile) : nullptr) {}

  bool sample(const SurfaceHit& hit, const Bsdf& bsdf, const glm::vec3& wo, VertexSamples& u, DirectionSample& out,
              PathStats& stats) override;
  float pdf(const SurfaceHit& hit, const Bsdf& bsdf, const glm::vec3& wo, const glm::vec3& wi, float bsdfPdf) override;
  void beginPath(uint64_t pixel) override {
    chainsUsedByPath_.clear();
    pixel_ = pixel;
    first_.cachePoint = -1;
  }
  void endPath(const glm::vec3& firstContinuation) override;
  void beginVertex(int depth) override {
    vertex_ = depth + 1;
    lastPosition_ = glm::vec3(NAN);  // a new vertex: look its cache point up again
  }

 private:
  // Probability of drawing from the BSDF at a vertex served by cache point c.
  float bsdfProbability(int c) const;
  // The mixture density of a direction, with its two parts for the learner; bsdfPdf is
  // bsdf.pdf(wo, wi) where the caller has it, negative where densities() must evaluate it.
  struct Densities {
    float bsdf = 0.0f, guide = 0.0f, mixture = 0.0f;
  };
  Densities densities(int c, const Bsdf& bsdf, const glm::vec3& wo, const glm::vec3& wi, float bsdfPdf = -1.0f) const;
  // The guide of cache point c for this pass.
  const GuideDistribution& guideAt(int c) const { return guides_ ? guides_->distribution(c) : field_.point(c).distribution; }
  // Whether this vertex reports to the learners: the first of its path, served by cache point c.
  bool learnsAt(int c) const { return (log_ || guideLog_) && vertex_ == 1 && c >= 0; }
  // Keeps the first vertex's direction and densities until endPath() knows what its continuation
  // brought back.
  void noteFirstVertex(int c, const glm::vec3& wi, const Densities& d) { first_ = {c, wi, d}; }
  // The cache point of a vertex; sample() and pdf() ask for the same vertex in a row, so remember it.
  int cachePoint(const SurfaceHit& hit);
  // The cache point that guides this vertex: none for a near-specular BSDF.
  int servingCachePoint(const SurfaceHit& hit, const Bsdf& bsdf);

  const GuideField& field_;
  SamplingMode mode_;
  std::unordered_map<int, MetropolisChain> chains_;
  // A path must not draw twice from one chain: the second state would depend on the first, and path
  // tracing needs each direction to have the sampling density given the path so far. A revisit
  // draws an exact sample of the same density instead.
  std::vector<int> chainsUsedByPath_;
  glm::vec3 lastPosition_{NAN}, lastNormal_{NAN};
  int lastCachePoint_ = -1;
  uint64_t pixel_ = 0;
  int vertex_ = 0;              // the current vertex, from 1 (the camera ray's hit)
  const SelectionLearner* learner_;
  SelectionLearner::TileLog* log_;
  const GuideLearner* guides_;
  GuideLearner::TileLog* guideLog_;
  struct {
    int cachePoint = -1;
    glm::vec3 wi{0.0f};
    Densities densities;
  } first_;
};

}  // namespace vpl
