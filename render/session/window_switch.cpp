#include "render/session/window_switch.h"

#include <algorithm>
#include "render/core/color.h"

namespace vpl {

bool WindowSwitch::update(const Film& film) {
  const Image mean = film.resolve();
  // Film::resolveVariance is the relative variance of the mean, var / n / (mean^2 + 1e-4): undone
  // per pixel, so that pixels weigh by their brightness.
  const Image relativeOfMean = film.resolveVariance();
  const double n = double(film.totalSamples()) / std::max<double>(1.0, double(mean.pixels.size()));
  double variance = 0.0, mean2 = 0.0;
  for (size_t i = 0; i < mean.pixels.size(); ++i) {
    const double m = luminance(mean.pixels[i]);
    variance += double(relativeOfMean.pixels[i].x) * n * (m * m + 1e-4);
    mean2 += m * m;
  }
  relativeVariance_ = mean2 > 0.0 ? variance / mean2 : 0.0;
  if (relativeVariance_ > kThreshold) on_ = true;
  return on_;
}

}  // namespace vpl
