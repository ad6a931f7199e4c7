// Refines each cache point's guide from what the paths bring back (issue 16, item 2).
//
// The VPL guide is a prior: it predicts where light comes from before any path is traced, but it is
// blind to what the clusters blur (a slit, a wall between a cluster and the cache point) and to the
// BSDF. The paths know better: at a cache point's first vertex, a direction w drawn with density q
// brings back F/q, the luminance of everything the rest of the path contributed (MIS-weighted, so
// what this continuation is responsible for). Summed into w's cell of the guide's own equal-area map,
// these records estimate each cell's share of the integral of F, the product that a perfect
// continuation would sample (Müller et al. 2017 learn incident radiance in the same way, on an
// adaptive tree). The cells are the guide's (1024 of 0.0123 sr): a cache point sees a few hundred
// first vertices a pass, so a cell's sum is noisy for long, but the pdf stays exact and MIS with the
// BSDF bounds what a noisy cell costs, while coarser learned cells blur a glossy lobe's light (per
// sample at 64 spp, cornell_glossy's relMSE 0.88x that of 8x8 learned cells, 16x16: 0.89x; 0.91x at
// 10 s; the diffuse scenes within 0.3 %: docs/measurements/learned_guide_resolution.md).
//
// Between passes every cache point's table becomes
//   (1 - lambda) prior + lambda learned,   lambda = n / (n + kPriorSamples)
// cell by cell, with n the samples the point has seen: the VPLs decide the first pass and give way as
// evidence comes in. Without a prior (--guide-prior none) the first pass is uniform and lambda is 1
// from the first sample on: a learned-only baseline close to practical path guiding.
// A table is fixed during a pass and depends only on earlier passes, so each pass stays an unbiased
// estimate with an exact pdf; the film sums them all.
//
// Threads: each tile of a pass writes its own log and nothing else; update() reads them all, in tile
// order, between passes, so the tables do not depend on thread count or schedule.
#pragma once
#include <array>
#include <cstdint>
#include <vector>
#include <glm/glm.hpp>
#include "render/guide/guide_field.h"
#include "render/guide/selection_learner.h"

namespace vpl {

class GuideLearner {
 public:
  static constexpr int kCells = GuideDistribution::kCells;  // learned at the guide's own cells
  // How many samples the VPL prior counts as: a cache point sees a few hundred per pass, so the
  // prior keeps about half the weight for the first pass or two (measured at 48 spp against 64:
  // within 1-6 % per scene, better on four of four, README).
  static constexpr double kPriorSamples = 512.0;

  class TileLog {
   public:
    // One first vertex at `cachePoint` continued in direction wi and brought back `value` (>= 0).
    void add(int cachePoint, const glm::vec3& wi, float value);

   private:
    friend class GuideLearner;
    struct Record {
      int32_t cachePoint;
      uint16_t cell;
      float value;
    };
    std::vector<Record> records_;
  };

  // `field` holds the priors and must outlive the learner. vplPrior false: learned only. defensive: the
  // uniform share of the learned tables (the priors keep the field's own).
  GuideLearner(const GuideField& field, int tiles, bool vplPrior, float defensive);

  // The guide of cache point c for the pass being rendered.
  const GuideDistribution& distribution(int c) const { return current_[size_t(c)]; }
  // The log that tile `tile` writes during a pass; only that tile's thread may touch it.
  TileLog& tileLog(uint32_t tile) { return tiles_[tile]; }
  // Merges the tiles' logs (in tile order) and rebuilds the tables of the cache points that saw
  // samples. Only between passes, when no tile is being rendered.
  void update();

  // The mean of lambda over cache points: how far the guides have moved from the VPLs (JSON line).
  double meanLearnedShare() const;

 private:
  GuideDistribution blend(int c) const;

  const GuideField& field_;
  bool vplPrior_;
  float defensive_;
  std::vector<GuideDistribution> current_;
  std::vector<std::array<double, kCells>> sums_;
  std::vector<uint32_t> samples_;
  std::vector<TileLog> tiles_;
};

// The learners a film's passes feed; either may be absent.
struct GuideLearners {
  SelectionLearner* selection = nullptr;
  GuideLearner* directions = nullptr;
};

}  // namespace vpl
