// Linear radiance to display sRGB. The PNG writer and the OpenGL display shader implement the same
// curve, so a headless capture can be compared with the render core's image.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace vpl {

// The sRGB opto-electronic transfer function (IEC 61966-2-1).
inline float linearToSrgb(float x) {
  if (!(x > 0.0f)) return 0.0f;
  if (x >= 1.0f) return 1.0f;
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}
inline float srgbToLinear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}
inline float exposureScale(float stops) { return std::exp2(stops); }
inline uint8_t toDisplayByte(float linear, float exposureStops) {
  return uint8_t(std::lround(255.0f * linearToSrgb(linear * exposureScale(exposureStops))));
}

}  // namespace vpl
