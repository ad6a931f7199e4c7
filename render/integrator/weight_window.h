// Russian roulette and splitting by a weight window (ADRRS, Vorba & Krivanek 2016), driven by the
// VPLs: at a path vertex x, the expected contribution of going on is the path's throughput times
// the radiance x reflects towards it, estimated from the VPLs' irradiance (IrradianceGrid); the
// pixel's own value is estimated the same way at the camera ray's hit. Their ratio is how much
// this path is worth against what the pixel needs. Below the window a path survives with a
// probability equal to the ratio, so that survivors carry about the pixel's value; above it, the
// continuation is split into about `ratio` branches of 1/n the weight. Both keep the estimator
// unbiased for any ratio: survivors are divided by their probability, branches share the weight.
//
// Parameters (WeightWindowSettings):
//   width        float  5     window [2/(1+width), 2 width/(1+width)] around 1 (their s)
//   maxSplit     int    8     most branches one vertex splits into
//   maxBranches  int    16    most paths one camera sample may grow into (bounds the cost per sample)
#pragma once
#include <algorithm>
#include <cmath>
#include <string>

namespace vpl {

struct WeightWindowSettings {
  float width = 5.0f;
  int maxSplit = 8;
  int maxBranches = 16;
  // A path is never killed with a probability above 1 - this: an estimate of zero light (no VPL
  // reached a cell) may be wrong, and survivors then carry at most 1/this of their weight.
  static constexpr float kMinSurvival = 0.05f;

  std::string validate() const {
    if (!(width >= 1.0f && width <= 1000.0f)) return "weight window width must be between 1 and 1000";
    if (maxSplit < 1 || maxSplit > 64) return "max split must be between 1 and 64";
    if (maxBranches < 1 || maxBranches > 1024) return "max branches must be between 1 and 1024";
    return {};
  }
};

struct WindowDecision {
  float survival = 1.0f;  // < 1: Russian roulette with this probability
  int split = 1;          // > 1: continue with this many branches
};

// ratio = expected contribution of the path from here / the pixel's estimate (both >= 0).
inline WindowDecision weightWindow(float ratio, const WeightWindowSettings& s) {
  const float lower = 2.0f / (1.0f + s.width), upper = s.width * lower;
  if (!(ratio >= 0.0f)) return {};
  if (ratio < lower) return {std::max(ratio, WeightWindowSettings::kMinSurvival), 1};
  if (ratio > upper) return {1.0f, int(std::min(std::ceil(ratio), float(s.maxSplit)))};
  return {};
}

}  // namespace vpl
