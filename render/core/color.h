// RGB helpers shared by the render core (linear Rec. 709 / sRGB primaries).
#pragma once
#include <cmath>
#include <glm/glm.hpp>

namespace vpl {

inline float luminance(const glm::vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
inline float maxComponent(const glm::vec3& c) { return glm::max(c.x, glm::max(c.y, c.z)); }
inline bool isFiniteNonNegative(const glm::vec3& c) {
  return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && c.x >= 0.0f && c.y >= 0.0f && c.z >= 0.0f;
}
inline bool isBlack(const glm::vec3& c) { return c.x <= 0.0f && c.y <= 0.0f && c.z <= 0.0f; }

}  // namespace vpl
