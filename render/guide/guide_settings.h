// Settings of the VPL guide (Hua & Low 2015; DESIGN.md §2 steps 6–8). Defaults follow the authors'
// released code where it applies ("Starting defaults" in DESIGN.md).
//
//   coneAngle          float  0.356  half-angle (radians, 20.4 deg: the authors' radius 0.1 on an equal-area map)
//   defensive          float  0.1    share of the uniform sphere density mixed into the guide pdf (measured: 0.01
//                                    leaves heavy tails in the guide-only modes)
//   misDefensive       float  0.02   the same share in mis's learned guides wherever mis's BSDF probability is at
//                                    least the learned one's least candidate, 0.1 (learned or fixed): the BSDF's share keeps the
//                                    mixture's density away from 0 where the guide has none, so the guide need not
//                                    spend a tenth of its samples on the whole sphere. Against 0.1 (seeds 1-4):
//                                    cornell_glossy's relMSE 0.95x per sample (64 spp, join depth fixed), 0.96x at
//                                    10 s, the interior 0.99x; the lanes' scenes within 0.5 % per sample. The
//                                    guide-only modes lose with 0.02 (mixture 1.33x on door_ajar, metropolis 3.4x on
//                                    one seed of cornell_glossy), so they keep `defensive` (film_learners.h;
//                                    docs/measurements/learned_guide_resolution.md)
//   uniformMutation    float  0.5    probability that a Metropolis mutation is an independent direction
//   perturbationAngle  float  0.157  half-angle (radians, 9 deg) of the local perturbation
//   mutations          int    1      Markov chain steps per requested direction
//   bsdfProbability    float  0.5    one-sample MIS: probability of sampling the BSDF instead of the guide (with
//                                    learnSelection: the prior of every cache point, until it has samples)
//   learnSelection     bool   true   mis: each cache point learns its probability from the paths between passes
//                                    (selection_learner.h, measured in the README's "The learned BSDF
//                                    probability"); false: the paper's fixed probability
//   learnDirections    bool   true   each cache point's guide learns from what the paths bring back between passes,
//                                    with the VPL guide as its prior (guide_learner.h; off: Hua & Low's guide).
//                                    Measured at 48 spp (seeds 2, 3): relMSE 0.97-0.98x on the Cornell box, 0.92-0.97x
//                                    on door_ajar, 0.95-0.96x on two_rooms and the interior, 0.79-0.80x on
//                                    cornell_glossy, for about 1 % more rays per sample and 1 % of the time
//   vplPrior           bool   true   learnDirections: start from the VPL guide; false: from a uniform one (a
//                                    learned-only baseline, --guide-prior none)
//   bilinear           bool   true   the guide's density interpolated between the cells' corners (false: constant
//                                    over each cell, as the paper's table; guide_distribution.h has the figures)
//   misChain           bool   false  mis: guide directions from the cache point's Markov chain (the paper); false:
//                                    exact samples of the guide from the BSDF's own stratified number
//   lookupCosNormal    float  0.9    a vertex uses a cache point only if their normals agree this well
//   lookupRadiusScale  float  1.5    ... and it lies within this multiple of the cache point's slice radius
//   guidedVertices     int    1      guide the first N vertices of a path only; 0: every vertex near a cache point.
//                                    Measured at equal spp (bench/measure_modes.sh scenes): guiding every vertex
//                                    left the per-sample error unchanged (within 4 %) and cost 25-45 % more time,
//                                    as the authors found; their choice, 1, is the default
//   switchToLanes      bool   true   mis: once the join depth's trial is over, BSDF samples in lanes take over
//                                    where the learned selection forecasts that the guide does not pay for
//                                    its one-at-a-time paths (render/session/guide_switch.h); false: the guide
//                                    throughout (--guide-switch off)
//   spreadScale        float  2      a cluster's cone is at least atan(spreadScale x its RMS spread / distance): the
//                                    angle its members subtend (measured: 2 cut the per-sample relMSE of `mixture`
//                                    5x on two_rooms and 11x on the interior against 0, and left `mis` unchanged)
#pragma once
#include <cmath>
#include <string>

namespace vpl {

struct GuideSettings {
  float coneAngle = 0.356f;
  float defensive = 0.1f;
  float misDefensive = 0.02f;
  float uniformMutation = 0.5f;
  float perturbationAngle = 0.157f;
  int mutations = 1;
  float bsdfProbability = 0.5f;
  bool learnSelection = true;
  bool learnDirections = true;
  bool vplPrior = true;
  bool bilinear = true;
  bool misChain = false;
  float lookupCosNormal = 0.9f;
  float lookupRadiusScale = 1.5f;
  float spreadScale = 2.0f;
  int guidedVertices = 1;
  bool switchToLanes = true;

  std::string validate() const {
    if (!(coneAngle > 1e-4f && coneAngle <= 3.1416f)) return "guide cone angle must be in (1e-4, pi] radians";
    if (!(defensive > 0.0f && defensive <= 1.0f)) return "defensive fraction must be in (0, 1]";
    if (!(misDefensive > 0.0f && misDefensive <= 1.0f)) return "mis defensive fraction must be in (0, 1]";
    if (!(uniformMutation >= 0.0f && uniformMutation <= 1.0f)) return "uniform mutation probability must be in [0, 1]";
    if (!(perturbationAngle > 0.0f && perturbationAngle <= 3.1416f)) return "perturbation angle must be in (0, pi]";
    if (mutations < 1 || mutations > 1000) return "mutations per sample must be between 1 and 1000";
    if (!(bsdfProbability >= 0.0f && bsdfProbability <= 1.0f)) return "BSDF selection probability must be in [0, 1]";
    if (!(lookupCosNormal >= -1.0f && lookupCosNormal <= 1.0f)) return "lookup normal cosine must be in [-1, 1]";
    if (!(lookupRadiusScale > 0.0f)) return "lookup radius scale must be positive";
    if (guidedVertices < 0) return "guided vertices must be 0 (all) or more";
    if (!(spreadScale >= 0.0f && spreadScale <= 1e3f)) return "cone spread scale must be in [0, 1000]";
    return {};
  }
};

}  // namespace vpl
