// Learns, per cache point, mis's probability of sampling the BSDF rather than the guide.
//
// Hua & Low fix it at 0.5 everywhere. Where the VPLs predict the incoming light well (a slit of
// light, a lit doorway) the guide should draw most directions; where the BSDF already follows the
// integrand (a diffuse box lit from above) every guide sample is wasted. Müller et al. (2019) learn
// this probability per region by gradient descent; here a few candidate probabilities are scored.
//
// Each guided first vertex reports its direction's BSDF and guide densities, the density it was
// drawn with, and what the rest of its path brought back (the continuation's estimate F / q). From
// those samples alone, the second moment of the estimator under every candidate mixture q_a is
// estimated by re-weighting: E_{q_a}[(F/q_a)^2] = E_q[(F/q)^2 q / q_a]. Between passes, each
// cache point with enough samples takes the least, or more BSDF within a margin of it (below); the
// others keep the prior. Where every path brought nothing back, every moment is 0 and the BSDF wins.
// A probability stays fixed during a pass and depends only on earlier passes, so each pass is still
// an unbiased estimate, with both densities exact.
//
// The second moment of independent samples misses what stratification gains, and that favours the
// BSDF's share: its directions are a stratified set over a smooth lobe. Taking the least moment
// chose the guide at 0.17 on the Cornell box and lost 6 % per sample there, so the choice is the
// candidate with the most BSDF whose moment is within kStratifiedMargin of the least, and the BSDF
// alone wherever its moment is within kBsdfOnlyMargin of the least: any guide share splits the
// pixel's stratified points between two strategies, each then stratified like fewer samples
// (docs/measurements/stratification.md).
//
// Threads: each tile of a pass writes its own log (TileLog) and nothing else; update() reads them
// all, in tile order, between passes, so the choice does not depend on thread count or schedule.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vpl {

class SelectionLearner {
 public:
  static constexpr std::array<float, 5> kCandidates{0.1f, 0.3f, 0.5f, 0.75f, 1.0f};
  static constexpr size_t kCount = kCandidates.size();
  // Samples a cache point needs before it leaves the prior: a second moment from fewer is mostly
  // noise (its estimate is heavy-tailed).
  static constexpr uint32_t kMinSamples = 32;
  // How much more second moment a candidate with more BSDF may have and still be chosen: 10 %
  // measured neutral (within 2 % per sample) on four scenes and 0.85x the relMSE on cornell_glossy;
  // 0 lost 6 % on the Cornell box, 25 % gave back half of cornell_glossy's gain.
  static constexpr double kStratifiedMargin = 0.1;
  // How much more second moment the BSDF alone (candidate 1) may have and still be chosen. On the
  // Cornell box (64 spp, seeds 1-4) a mixture gained 0.476x per sample from stratification where
  // brdf gained 0.469x; with 0.25 mis gained 0.458x and its error fell 1.4 %, while cornell_glossy,
  // two_rooms and door_ajar moved within their seeds' noise (-0.3 %, -0.6 %, -0.6 %); 0.15 changed
  // too few cache points (0.473x), 0.4 no more than 0.25 elsewhere.
  static constexpr double kBsdfOnlyMargin = 0.25;

  class TileLog {
   public:
    // One first vertex at `cachePoint`: its direction's densities under the BSDF, the guide and the
    // mixture it was drawn from, and the luminance of its continuation's estimate.
    void add(int cachePoint, float bsdfPdf, float guidePdf, float drawnPdf, float estimate);

   private:
    friend class SelectionLearner;
    struct Entry {
      int cachePoint = -1;
      uint32_t samples = 0;
      std::array<double, kCount> moment{};
    };
    std::vector<Entry> entries_;  // a tile sees few cache points: a short list, searched from the back
  };

  SelectionLearner() = default;
  SelectionLearner(size_t cachePoints, int tiles, float prior);

  // The probability at a cache point for the pass being rendered.
  float bsdfProbability(int cachePoint) const { return probability_[size_t(cachePoint)]; }
  // The log that tile `tile` writes during a pass; only that tile's thread may touch it.
  TileLog& tileLog(uint32_t tile) { return tiles_[tile]; }
  // Merges the tiles' logs (in tile order) and chooses each cache point's probability. Only between
  // passes, when no tile is being rendered.
  void update();

  // The mean chosen probability over cache points with enough samples (-1 if none): for the JSON
  // line and the viewer's panel.
  double meanLearnedProbability() const;
  // What the learned probabilities gain over the BSDF alone at the first vertex: the second moment of
  // the continuations' estimates with each cache point's chosen probability over that with the BSDF
  // alone, summed over the cache points with enough samples (1: the guide takes nothing off; -1:
  // no cache point has enough samples yet).
  double guideGain() const;

 private:
  std::vector<float> probability_;
  std::vector<uint32_t> samples_;
  std::vector<std::array<double, kCount>> moment_;
  std::vector<TileLog> tiles_;
};

}  // namespace vpl
