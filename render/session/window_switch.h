// When the VPL weight window pays: the switch of the `auto` roulette rule (path_tracer.h).
//
// Splitting and roulette by an estimate of what a path is worth pay off when a pixel's samples
// vary far more than their mean, as where all light arrives through a slit: the continuation from
// a vertex is then about as uncertain as the whole pixel, the case where the adjoint-driven window
// is the efficient choice (Rath et al. 2022 give the general rule). Where samples vary little (a
// lit Cornell box: 0.07 relative variance per sample) or moderately (two_rooms: about 2), the
// window raised the equal-time error 1.4-3x (bench/vs_cycles.sh, docs/roulette/vpl_window.md).
// So the render switches to the window when the image's samples, from its first passes, vary more
// than their mean: relative variance (brightness-weighted) above kThreshold. Measured after 2 and
// 4 passes: door_ajar 1.5 and 2.2 (on); the interior 0.57 and 0.66, two_rooms 0.50 and 0.53,
// the Cornell boxes 0.03-0.07 (off), where the window lost 1.4-3x. The statistic creeps up with
// more passes as rare bright samples arrive (the interior: 0.72 at 16), so it is read early only.
// The decision is for the whole image: per 16x16 tile, two to four samples per pixel misjudged
// too many tiles. A rule tuned on five scenes: the README's tables say how it fares.
#pragma once
#include <cstdint>
#include "render/film/film.h"

namespace vpl {

class WindowSwitch {
 public:
  static constexpr double kThreshold = 1.0;

  // True after `passes` complete passes when update() should be called: after 2 and 4.
  static bool updateDue(uint64_t passes) { return passes == 2 || passes == 4; }
  // Reads the film's relative variance per sample (Film::sampleRelativeVariance); switches on above
  // kThreshold. Once on, it stays on: the film then mixes both rules' samples. Returns on().
  bool update(const Film& film);
  bool on() const { return on_; }
  // The statistic of the last update.
  double relativeVariance() const { return relativeVariance_; }

 private:
  bool on_ = false;
  double relativeVariance_ = 0.0;
};

}  // namespace vpl
