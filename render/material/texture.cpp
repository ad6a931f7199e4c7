#include "render/material/material.h"

#include <cmath>

namespace vpl {

glm::vec4 Texture::sample(glm::vec2 uv) const {
  if (width <= 0 || height <= 0) return glm::vec4(1.0f);
  // Texel centres at half-integers; repeat wrapping as glTF's default sampler.
  const float x = uv.x * float(width) - 0.5f, y = uv.y * float(height) - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float tx = x - fx, ty = y - fy;
  auto wrap = [](long v, int n) { long m = v % n; return int(m < 0 ? m + n : m); };
  if (!std::isfinite(fx) || !std::isfinite(fy)) return texels[0];
  const int x0 = wrap(long(fx), width), x1 = wrap(long(fx) + 1, width);
  const int y0 = wrap(long(fy), height), y1 = wrap(long(fy) + 1, height);
  const glm::vec4 a = texels[size_t(y0) * width + x0], b = texels[size_t(y0) * width + x1];
  const glm::vec4 c = texels[size_t(y1) * width + x0], d = texels[size_t(y1) * width + x1];
  return (a * (1 - tx) + b * tx) * (1 - ty) + (c * (1 - tx) + d * tx) * ty;
}

}  // namespace vpl
