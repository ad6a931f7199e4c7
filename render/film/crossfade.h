// A linear mix of two images of one size: the viewer's hand-over from the VPL preview to the path-traced
// film, which fades in as its samples accumulate instead of replacing the preview in one step.
#pragma once
#include <algorithm>
#include "render/film/image.h"

namespace vpl {

// (1 - t) from + t to, t clamped to [0, 1]; t = 1 returns `to` exactly.
inline Image crossfade(const Image& from, const Image& to, float t) {
  t = std::clamp(t, 0.0f, 1.0f);
  if (t >= 1.0f || from.pixels.size() != to.pixels.size()) return to;
  Image out(to.width, to.height);
  for (size_t i = 0; i < out.pixels.size(); ++i) out.pixels[i] = from.pixels[i] + t * (to.pixels[i] - from.pixels[i]);
  return out;
}

}  // namespace vpl
