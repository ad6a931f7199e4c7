// A ray's hit point with everything shading needs: position, normals, texture coordinates.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>

namespace vpl {

struct SurfaceHit {
  glm::vec3 position{0.0f};
  glm::vec3 geometricNormal{0, 0, 1};  // unit, turned to face the incoming ray (towards wo)
  glm::vec3 shadingNormal{0, 0, 1};    // unit, interpolated, on the same side as geometricNormal
  glm::vec2 uv0{0.0f}, uv1{0.0f};
  uint32_t mesh = 0, triangle = 0, material = 0;
  bool frontFace = true;  // the ray arrived on the side the triangle's winding faces
  float coordinateScale = 1.0f;  // largest |coordinate| of the triangle's vertices: the hit point's rounding scale
};

}  // namespace vpl
