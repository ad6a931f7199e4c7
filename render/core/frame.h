// An orthonormal shading frame; local coordinates have the normal on +z.
#pragma once
#include <glm/glm.hpp>

namespace vpl {

struct Frame {
  glm::vec3 s{1, 0, 0}, t{0, 1, 0}, n{0, 0, 1};

  // Branchless basis from a unit normal (Duff et al., "Building an Orthonormal Basis, Revisited", 2017).
  static Frame fromNormal(const glm::vec3& n) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    Frame f;
    f.n = n;
    f.s = glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.t = glm::vec3(b, sign + n.y * n.y * a, -n.y);
    return f;
  }
  glm::vec3 toLocal(const glm::vec3& v) const { return {glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)}; }
  glm::vec3 toWorld(const glm::vec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

}  // namespace vpl
