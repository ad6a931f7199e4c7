#include "render/session/window_switch.h"

namespace vpl {

bool WindowSwitch::update(const Film& film) {
  relativeVariance_ = film.sampleRelativeVariance();
  if (relativeVariance_ > kThreshold) on_ = true;
  return on_;
}

}  // namespace vpl
